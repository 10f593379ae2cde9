/* serve_config.c - the emulator's configuration: the `serve:` section, the
 * trigger sources and the `outputs:` list (serve_internal.h). Reads and
 * opens; starts nothing. */
#include <arpa/inet.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "core/params.h"
#include "emulator/driver.h"
#include "emulator/serve_internal.h"

const char *const nc__serve_mode_names[] = {"lockstep", "freerun", "trigger", NULL};

/* The built-in software source (TRIGGER messages, POSE with CAPTURE, a
 * client's TriggerSoftware) takes only the common keys. */
/* `serve.trigger`: a line driver, or the built-in software source. check:
 * a line driver's options are checked, not opened (the software source
 * opens nothing; its settings are set again by the real pass). */
static int open_trigger(struct nc__emu *e, struct nc_cfg_node *tr, int check)
{
    int rc, builtin = 0;
    const struct nc_trigger_driver *d = nc_registry_select_trigger(e->drivers, tr, "software", &builtin, &rc);
    if (builtin) {
        /* Software commands: no line, so no activation or debounce; the
         * common keys' delay_s alone. */
        double delay_s = 0;
        if (tr && tr->kind != NC_CFG_MAP)
            return nc_cfg_error(tr, "expected a map of keys for trigger source 'software'");
        for (size_t i = 0; tr && i < tr->nchild; i++) {
            const struct nc_cfg_node *c = tr->child[i];
            if (!strcmp(c->key, "activation") || !strcmp(c->key, "debounce_s"))
                return nc_cfg_error(c, "trigger source 'software' gives commands, not line edges: activation and "
                                       "debounce_s do not apply (it takes: driver, delay_s)");
            if (strcmp(c->key, "driver") && strcmp(c->key, "delay_s"))
                return nc_cfg_error(c, "unknown key for trigger source 'software' (it takes: driver, delay_s)");
        }
        if ((rc = nc_param_double(tr, nc_trigger_common_params, "delay_s", &delay_s)) < 0)
            return rc;
        e->software_configured = 1;
        e->acq.trigger_delay_s = delay_s;
        return 0;
    }
    if (!d || check)
        return d ? nc_trigger_check(d, tr) : rc;
    if ((rc = nc_trigger_open(&e->line, d, tr, nc__serve_on_line, e)) < 0)
        return rc;
    e->have_line = 1;
    e->acq.source = NC_SOURCE_LINE;
    e->acq.activation = nc_trigger_activation(&e->line);
    e->acq.trigger_delay_s = nc_trigger_delay_ns(&e->line) * 1e-9;
    return 0;
}

static int open_outputs(struct nc_cfg *cfg, struct nc__emu *e, const char *config_dir, int check)
{
    struct nc_output_ctx ctx = {e->scene.camera.width_px, e->scene.camera.height_px, e->cs.sensor.adc_bits, config_dir,
                                &e->control};
    struct nc_cfg_node *outs = NULL;
    int rc;
    if ((rc = nc_cfg_seq(cfg->root, "outputs", &outs)) < 0)
        return rc;
    if (!outs) { /* default: numbered PNG files and the sidecar under out/ */
        if ((rc = nc_cfg_set(cfg, "outputs=[{driver: file, directory: out}]")) < 0 ||
            (rc = nc_cfg_seq(cfg->root, "outputs", &outs)) < 0)
            return rc;
    }
    if (outs->nchild == 0 || outs->nchild > NC_SERVE_MAX_OUTPUTS)
        return nc_cfg_error(outs, "expected 1 to %d outputs", NC_SERVE_MAX_OUTPUTS);
    for (size_t i = 0; i < outs->nchild; i++) {
        struct nc_cfg_node *o = outs->child[i];
        o->used = 1;
        if (o->kind != NC_CFG_MAP)
            return nc_cfg_error(o, "expected a map with 'driver' and its options");
        const struct nc_output_driver *d = nc_registry_select_output(e->drivers, o, &rc);
        if (!d)
            return rc;
        if (check)
            rc = nc_output_check(d, o);
        else if ((rc = nc_output_open(&e->out[e->nout], d, o, &ctx)) >= 0)
            e->nout++;
        if (rc < 0)
            return rc;
    }
    return 0;
}

/* An int setting: *out keeps its default unless the key is there. */
static int int_key(struct nc_cfg_node *map, const char *key, long min, long max, int *out)
{
    long v = *out;
    int rc = nc_cfg_int(map, key, min, max, &v);
    *out = (int)v;
    return rc;
}

int nc__serve_config(struct nc_cfg *cfg, struct nc__emu *e, const char *config_dir, int check)
{
    struct nc_cfg_node *sv = NULL;
    int rc, m = NC__MODE_FREERUN;
    e->no_pose_scene = 1;
    e->frame_rate_hz = 10;
    e->queue_frames = 4;
    e->stats_interval_s = 5;
    double max_extrap = 0.5, pose_wait_s = 0;
    snprintf(e->bind, sizeof e->bind, "127.0.0.1");
    e->udp_port = 5750;
    e->tcp_port = 5751;
    e->max_clients = 64;
    e->overlap = 1;
    if ((rc = nc_cfg_map(cfg->root, "serve", &sv)) < 0)
        return rc;
    if (sv) {
        static const char *const drops[] = {"drop_newest", "drop_oldest", NULL};
        static const char *const stale[] = {"drop", "render", NULL};
        static const char *const nopose[] = {"scene", "drop", NULL};
        static const char *const onoff[] = {"false", "true", NULL};
        int np = 0, ov = 1;
        const char *bind = NULL;
        int d = 0, st = 0;
        if ((rc = nc_cfg_enum(sv, "mode", nc__serve_mode_names, &m)) < 0 ||
            (rc = nc_cfg_double(sv, "frame_rate_hz", 1e-3, 1000, &e->frame_rate_hz)) < 0 ||
            (rc = nc_cfg_double(sv, "stats_interval_s", 0, 3600, &e->stats_interval_s)) < 0 ||
            (rc = nc_cfg_double(sv, "max_extrapolation_s", 0, 3600, &max_extrap)) < 0 ||
            (rc = nc_cfg_double(sv, "pose_wait_s", 0, 60, &pose_wait_s)) < 0 ||
            (rc = nc_cfg_enum(sv, "drop_policy", drops, &d)) < 0 || (rc = nc_cfg_enum(sv, "stale_pose", stale, &st)) < 0 ||
            (rc = nc_cfg_enum(sv, "no_pose", nopose, &np)) < 0 || (rc = nc_cfg_string(sv, "bind", &bind)) < 0 ||
            (rc = nc_cfg_enum(sv, "overlap_camera_model", onoff, &ov)) < 0)
            return rc;
        e->overlap = ov;
        e->drop_oldest = d;
        e->no_pose_scene = np == 0;
        e->stale_render = st;
        struct in_addr ip;
        if (bind && inet_pton(AF_INET, bind, &ip) != 1)
            return nc_cfg_key_error(sv, "bind", "'%s' is not an IPv4 address (a name is not looked up)", bind);
        if (bind)
            snprintf(e->bind, sizeof e->bind, "%s", bind);
        if ((rc = int_key(sv, "queue_frames", 1, 1024, &e->queue_frames)) < 0 ||
            (rc = int_key(sv, "udp_port", 0, 65535, &e->udp_port)) < 0 ||
            (rc = int_key(sv, "tcp_port", 0, 65535, &e->tcp_port)) < 0 ||
            (rc = int_key(sv, "max_clients", 1, 1000, &e->max_clients)) < 0)
            return rc;
    }
    e->mode = (enum nc__serve_mode)m;
    e->overlap = e->overlap && e->mode != NC__MODE_LOCKSTEP;
    e->pose_wait_ns = llround(pose_wait_s * 1e9);
    struct nc_cfg_node *tr = NULL;
    if (sv && (rc = nc_cfg_map(sv, "trigger", &tr)) < 0)
        return rc;
    if (tr && e->mode == NC__MODE_LOCKSTEP)
        return nc_cfg_error(tr, "serve.trigger does not apply to lock-step mode (frames follow POSE messages with "
                                "CAPTURE)");
    if (check) {
        if ((tr && (rc = open_trigger(e, tr, 1)) < 0) || (rc = open_outputs(cfg, e, config_dir, 1)) < 0)
            return rc;
        struct nc_cfg_node *outs = nc_cfg_get(cfg->root, "outputs");
        if ((sv && (rc = nc_cfg_check_unused_in(cfg, sv)) < 0) || (rc = nc_cfg_check_unused_in(cfg, outs)) < 0)
            return rc;
        return 0;
    }
    if ((rc = nc_timeline_init(&e->tl, 4096, (int64_t)llround(max_extrap * 1e9))) < 0)
        return rc;
    /* The initial acquisition settings; serve.trigger may change the source. */
    e->acq = (struct nc_acquisition){
        .triggered = e->mode == NC__MODE_TRIGGER,
        .source = NC_SOURCE_SOFTWARE,
        .activation = NC_TRIGGER_RISING,
        .frame_rate_hz = e->frame_rate_hz,
        .exposure_s = e->cs.exposure_s,
        .gain_db = e->cs.sensor.analog_gain_db,
    };
    if (tr && (rc = open_trigger(e, tr, 0)) < 0)
        return rc;
    if (e->mode != NC__MODE_LOCKSTEP) {
        /* The camera's own clock for free-run: a timer at the frame rate,
         * opened with its defaults (no configuration text) and set to the rate. */
        const struct nc_trigger_driver *timer = nc_registry_trigger(e->drivers, "timer");
        if (!timer)
            return nc_error(NC_EUNSUPPORTED, "serve: free-run needs the timer trigger driver, which this program lacks");
        if ((rc = nc_trigger_open(&e->freerun, timer, NULL, nc__serve_on_freerun, e)) < 0 ||
            (rc = nc_trigger_control(&e->freerun, "rate_hz", &e->frame_rate_hz)) < 0)
            return rc;
        e->have_freerun = 1;
    }
    nc__serve_enable_sources(e);
    return open_outputs(cfg, e, config_dir, 0);
}
