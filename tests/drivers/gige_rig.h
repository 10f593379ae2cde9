/* gige_rig.h - the test rig of test_gige.c: `navcam serve` with the gige
 * output started as a child process, a libaravis client opened on it by
 * 127.0.0.1, frames with their metadata row, the file output's frames to
 * compare with. */
#ifndef NC_TEST_GIGE_RIG_H
#define NC_TEST_GIGE_RIG_H

#include <arv.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#define W 128
#define H 96
#define BITS 12
#define BIAS 64

extern const char *navcam, *tmp;
extern unsigned long incomplete; /* buffers that arrived with missing packets */
extern unsigned long unfilled;   /* buffers Aravis gave back as they were (start()'s datagrams) */
extern uint64_t frame_id;        /* the GVSP block id of the last frame next_frame returned */
extern uint64_t frame_arrived_ns; /* and when Aravis received it (its system timestamp: CLOCK_REALTIME, ns) */
extern int rig_packet_size;      /* GevSCPSPacketSize open_camera sets (8192: frames of several packets); 0: as is */

struct stream {
    ArvStream *s;
    size_t payload;
};

/* The tests' command line, NAVCAM TMPDIR, into navcam and tmp (absolute
 * paths: serve runs in its own directory); SIGPIPE ignored, stdout line
 * buffered. Returns 0, or -1 after a usage message. */
int rig_args(int argc, char **argv, const char *prog);
double now_s(void);
/* Start `navcam serve` in dir with the common small, noise-free scene plus
 * extra --set arguments; stderr goes to dir/serve.log. */
pid_t serve(const char *dir, const char *const *extra, int nextra);
int stop(pid_t pid);
/* The camera at 127.0.0.1 once the device answers (up to 15 s). */
ArvCamera *open_camera(void);
/* serve in tmp/name with one output map, and a camera opened on it; NULL
 * (serve stopped) when no camera answers. */
ArvCamera *begin(const char *name, const char *outputs, const char *more, pid_t *pid, char *dir,
                  size_t dirlen);
/* A stream with 8 buffers, and AcquisitionStart. */
int start(ArvCamera *c, struct stream *st);
void finish(ArvCamera *c, struct stream *st);
/* The next complete frame within timeout_s, copied into out (payload bytes);
 * its GVSP timestamp in *ts. Returns 0, or -1 on timeout. */
int next_frame(struct stream *st, double timeout_s, uint8_t *out, uint64_t *ts);
uint64_t le64(const uint8_t *p);
double f64(const uint8_t *p);
/* The metadata row's 48-byte core: magic, CRC; frame number, exposure and
 * gain out. */
int meta(const uint8_t *row, uint64_t *frame, double *exposure_s, double *gain_db);
/* The file output's DN frame number n (EXR: exact float DN). */
float *file_frame(const char *dir, uint64_t n);
/* Pixels of a received frame (after the metadata row) against the file:
 * format bits per pixel, shift, ROI. Returns the number of differences. */
long compare(const uint8_t *img, const float *dn, int bpp, int shift, int ox, int oy, int w, int rows);

#endif
