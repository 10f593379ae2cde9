/* serve.h - `navcam serve`: the real-time camera emulator. Poses arrive over
 * UDP/TCP (navcam/protocol.h) into the pose timeline; triggers (lock-step
 * capture requests, software triggers, a free-run timer, a trigger line)
 * become frame jobs; a render thread renders and digitises them; an output
 * thread hands each frame to every configured output driver (output.h) and
 * answers lock-step requests. Queues between the stages are bounded; pose
 * input never waits on them.
 * A library: it installs no signal handler and names no driver. The program
 * hands it the drivers it has and a flag its signal handlers set.
 */
#ifndef NC_SERVE_H
#define NC_SERVE_H

#include <signal.h>
#include <stdint.h>

#include "emulator/driver.h"

struct nc_serve_options {
    const char *scene_path;       /* NULL: built-in default scene */
    const char *const *sets;      /* --set overrides */
    int nsets;
    long max_frames;              /* stop after this many frames have been delivered or dropped (0: no limit) */
    double max_seconds;           /* stop after this long (0: no limit) */
    const char *stats_json_path;  /* also write the summary here (NULL: stdout only) */
    int threads;                  /* render threads (0: config, then all cores) */
    const struct nc_driver_registry *drivers; /* the output and trigger drivers to choose from */
    const volatile sig_atomic_t *stop; /* non-zero: shut down (set from a signal handler); may be NULL */
};

/* Runs until *opt->stop (or a limit above); returns 0 after a clean
 * shutdown, negative with a message on a setup error. */
int nc_serve(const struct nc_serve_options *opt);

#endif
