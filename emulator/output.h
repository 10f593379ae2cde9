/* output.h - the output driver interface and the frame record every driver
 * receives. Modelled on mpv's video outputs: each driver is one constant
 * struct (name, description, capabilities, private state size, functions);
 * a registry selects drivers by name; the emulator never knows a particular
 * driver. Drivers live in drivers/, one file each, exporting one symbol.
 */
#ifndef NC_OUTPUT_H
#define NC_OUTPUT_H

#include <stddef.h>
#include <stdint.h>

#include "core/config.h"
#include "core/params.h"
#include "core/pose.h"
#include "emulator/trigger.h"

struct nc_image_attr;

/* Everything known about one delivered frame. The pixel buffers belong to
 * the emulator and are valid during submit() only. */
struct nc_frame_record {
    uint64_t frame;              /* 0, 1, 2, ... in delivery order */
    uint32_t request_sequence;   /* sequence of the message that asked for it; 0 for timer frames */
    const char *trigger_source;  /* "lockstep", "software", "timer" */
    int64_t trigger_sim_ns, exposure_start_sim_ns, exposure_end_sim_ns;
    int64_t trigger_mono_ns, exposure_start_mono_ns, exposure_end_mono_ns; /* CLOCK_MONOTONIC */
    struct nc_pose pose;         /* the interpolated pose actually used (mid-exposure) */
    enum nc_pose_quality pose_quality;
    int64_t pose_gap_ns;         /* how far the pose was extrapolated */
    double exposure_s, gain_db;
    int time_samples;            /* motion-smear time samples */
    double lod_error_m;          /* error bound of the meshes' levels of detail used, m (0: full meshes) */
    double boulder_min_m;        /* the boulder cut, m: rocks this size and larger traced (0: every rock, or none) */
    double boulder_mesh_px;      /* rocks of this many pixels or more traced as detailed surfaces (0: none) */
    double rock_fold_theta_bar_deg; /* roughness the rocks not traced were folded into, deg (-1: none) */
    int samples_per_pixel, bounces, soft_shadows, quality_auto; /* the render settings used (auto: its choice) */
    int stars_on;                   /* the scene has a `stars` section: */
    double star_limit_mag;          /* the limiting magnitude used */
    long stars_drawn, stars_hidden; /* stars in the frame, and hidden by bodies */
    double sun_off_axis_deg, sun_edge_deg; /* the Sun from the boresight, and from the frame's edge (< 0: in it) */
    int sun_in_field, sun_near_field, sun_hidden;
    unsigned long hit_samples, back_samples; /* camera samples that met a surface, and its back side */
    long in_rock1; /* the boulder the camera is inside (of body in_rock_body), plus 1 (0: none) */
    int in_rock_body;
    double render_ms, camera_ms; /* render (incl. smear) and camera model time */
    int width_px, height_px, adc_bits;
    const uint16_t *dn;          /* the digitised frame */
    /* The frame's metadata as image attributes (render/image_io.h), as
     * navcam render gives a dn frame's: the camera and Sun at its pose,
     * the camera model, the detail, a celestial WCS with stars; valid
     * during submit. */
    const struct nc_image_attr *attrs;
    int nattrs;
};

/* One JSON object (no newline) describing a record; returns its length or a
 * negative value when len is too small. Without wall_clock the
 * CLOCK_MONOTONIC times and the render and camera-model durations are left
 * out: what remains is reproducible (lock-step runs give identical text). */
int nc_frame_record_json(const struct nc_frame_record *r, int wall_clock, char *buf, size_t len);

enum nc_output_caps {
    NC_OUTPUT_CAP_DN16 = 1u << 0, /* takes 16-bit DN frames */
};

/* The camera's acquisition settings, which a driver may hand to its clients
 * (GenICam features, V4L2 controls). They apply from the next exposure. */
enum nc_trigger_source { NC_SOURCE_SOFTWARE, NC_SOURCE_LINE };
struct nc_acquisition {
    int triggered;                         /* 0: free-run at frame_rate_hz; 1: a frame per trigger */
    enum nc_trigger_source source;         /* when triggered: software commands, or the line (serve.trigger) */
    enum nc_trigger_activation activation; /* of the line */
    double frame_rate_hz, exposure_s, gain_db, trigger_delay_s;
};

/* The emulator's side, valid from open() to close(); callable from any
 * thread. In lock-step mode frames follow the poses: set() takes exposure
 * and gain and refuses a change of triggering (NC_EUNSUPPORTED). */
struct nc_camera_control {
    void *emu;
    void (*get)(void *emu, struct nc_acquisition *a);
    int (*set)(void *emu, const struct nc_acquisition *a);
    /* A software trigger now (counted as ignored unless triggered by software). */
    void (*software_trigger)(void *emu);
    /* The frame rate the camera delivers now, Hz: the requested free-run
     * rate capped by what the render allows (0: not known yet). */
    double (*resulting_rate_hz)(void *emu);
};

struct nc_output_ctx {
    int width_px, height_px, adc_bits;
    const char *config_dir;                   /* for relative paths */
    const struct nc_camera_control *control;  /* NULL outside `navcam serve` */
};

struct nc_output_driver {
    const char *name;
    const char *description;
    unsigned caps;
    size_t priv_size;
    const struct nc_param *params; /* the keys of the driver's map in `outputs:` (besides `driver`) */
    /* The driver's checks of its values that need no device (a file name's
     * form, keys that must agree), run with the tables' before the scene is
     * built (nc_output_check) and again at open; NULL: none. */
    int (*check)(struct nc_cfg_node *opts);
    /* Options come from the driver's map in `outputs:`, checked against params. */
    int (*open)(void *priv, struct nc_cfg_node *opts, const struct nc_output_ctx *ctx);
    int (*submit)(void *priv, const struct nc_frame_record *r);
    /* Generic hook (e.g. "flush"); NULL means every request is unsupported. */
    int (*control)(void *priv, const char *request, void *arg);
    void (*close)(void *priv);
};

/* An opened driver instance. */
struct nc_output {
    const struct nc_output_driver *drv;
    void *priv;
    unsigned long submitted, failed;
};

/* A frame's record as a binary block, the metadata row of the GigE and V4L2
 * outputs (docs/gige.md "The metadata row"): little-endian, a 48-byte core
 * with its own CRC-32 (frame number, exposure start, time and gain, the
 * request's sequence), then the trigger and exposure times, the pose and
 * the ADC's bits, with a CRC-32 over the block. */
#define NC_FRAME_META_BYTES 160
/* The block at the start of row (len bytes), the rest of it 0: a row
 * shorter than the block holds its beginning. */
void nc_frame_metadata_row(const struct nc_frame_record *r, uint8_t *row, size_t len);

/* opts against the driver's table: every key known (unknown keys:
 * file:line), every value of its type and range. Touches nothing. */
int nc_output_check(const struct nc_output_driver *drv, struct nc_cfg_node *opts);
/* nc_output_check, then opens it. */
int nc_output_open(struct nc_output *o, const struct nc_output_driver *drv, struct nc_cfg_node *opts,
                   const struct nc_output_ctx *ctx);
int nc_output_submit(struct nc_output *o, const struct nc_frame_record *r);
int nc_output_control(struct nc_output *o, const char *request, void *arg);
void nc_output_close(struct nc_output *o);

#endif
