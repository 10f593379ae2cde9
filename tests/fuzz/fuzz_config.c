/* fuzz_config.c - libFuzzer target: the configuration loader (libyaml tree,
 * overrides, typed readers, unknown-key check) on arbitrary text. It must
 * never crash, leak or read out of bounds, whatever the input. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    if (nc_cfg_load_string(&cfg, text, "fuzz.yaml") == 0) {
        /* Exercise the readers the scene loader uses. */
        struct nc_cfg_node *cam = NULL, *b = NULL;
        double d;
        long l;
        struct nc_vec3 v;
        struct nc_quat q;
        const char *s;
        if (nc_cfg_map(cfg.root, "camera", &cam) > 0) {
            nc_cfg_double(cam, "focal_length_m", 0, 1, &d);
            nc_cfg_int(cam, "width_px", 1, 16384, &l);
            nc_cfg_vec3(cam, "position_m", &v);
            nc_cfg_quat(cam, "attitude_q", &q);
            nc_cfg_string(cam, "name", &s);
        }
        nc_cfg_seq(cfg.root, "bodies", &b);
        nc_cfg_set(&cfg, "camera.position_m=[1, 2, 3]");
        nc_cfg_set(&cfg, "bodies.0.shape.radius_m=5");
        nc_cfg_check_unused(&cfg);
    }
    nc_cfg_free(&cfg);
    free(text);
    return 0;
}
