/* serve.h - `navcam serve`: the real-time camera emulator. Poses arrive over
 * UDP/TCP (protocol.h) into the pose timeline; triggers (lock-step capture
 * requests, software triggers, a free-run timer) become frame jobs; a render
 * thread renders and digitises them; an output thread hands each frame to
 * every configured output driver (output.h) and answers lock-step requests.
 * Queues between the stages are bounded; pose input never waits on them.
 */
#ifndef NC_SERVE_H
#define NC_SERVE_H

#include <stdint.h>

struct nc_serve_options {
    const char *scene_path;       /* NULL: built-in default scene */
    const char *const *sets;      /* --set overrides */
    int nsets;
    long max_frames;              /* stop after this many frames have been delivered or dropped (0: no limit) */
    double max_seconds;           /* stop after this long (0: no limit) */
    const char *stats_json_path;  /* also write the summary here (NULL: stdout only) */
    int threads;                  /* render threads (0: config, then all cores) */
};

/* Runs until SIGINT/SIGTERM (or a limit above); returns 0 after a clean
 * shutdown, negative with a message on a setup error. */
int nc_serve(const struct nc_serve_options *opt);

#endif
