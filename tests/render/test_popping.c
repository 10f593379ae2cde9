/* test_popping.c - detail does not pop: as the camera closes in, the mesh's
 * level of detail (render.lod_error_px) and the boulder cut
 * (render.boulder_min_px, the rest folded into the roughness) change with
 * the range, and each change may move the body's total brightness by at
 * most a stated tolerance beyond what the range step itself does. The range
 * step's own change is measured on a reference without the switching
 * detail (the full mesh; the bare body, whose frame has no sub-pixel rocks
 * to alias), at both ranges; the pop is the ratio of the two changes,
 * minus 1. NC_POP_DEBUG=1 prints every change. */
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "testutil.h"

/* rock_px < 0: the bare body (every rock cut, nothing folded) */
static double flux(struct nc_renderer *r, struct nc_scene *s, double range_m, double lod_px, double rock_px,
                   struct nc_frame *f, struct nc_rt_stats *st)
{
    s->camera.position_m = nc_v3(0, -range_m, 0);
    s->render.lod_error_px = lod_px;
    s->render.boulder_min_px = rock_px < 0 ? 1000 : rock_px;
    s->render.boulder_fold = rock_px >= 0;
    CHECK(nc_render_frame(r, s, f) == 0, "%s", nc_errmsg());
    nc_rt_get_stats(r->rt, st);
    double sum = 0;
    for (size_t i = 0; i < (size_t)f->width_px * f->height_px; i++)
        sum += f->radiance[i];
    return sum;
}

/* Sweep the range from far to near in steps of 5 %; at each step where
 * what is traced changes, the pop against the reference. */
static void sweep(const char *what, struct nc_scene *s, double from_m, double lod_px, double rock_px, double tol,
                  double near_m, double tol_near, int expect_changes)
{
    struct nc_renderer r;
    struct nc_frame f;
    struct nc_rt_stats st;
    s->render.lod_error_px = lod_px; /* levels are built only when asked for */
    CHECK(nc_renderer_init(&r, s, 2) == 0 && nc_frame_alloc(&f, s->camera.width_px, s->camera.height_px) == 0, "%s",
          nc_errmsg());
    double worst = 0, worst_near = 0, range = from_m;
    int changes = 0;
    double prev = flux(&r, s, range, lod_px, rock_px, &f, &st);
    long key_prev = (long)st.lod_level[0] * 100000000L + (long)st.boulders_traced[0];
    while (range * 0.95 > 1400) {
        double next_range = range * 0.95;
        double now = flux(&r, s, next_range, lod_px, rock_px, &f, &st);
        long key = (long)st.lod_level[0] * 100000000L + (long)st.boulders_traced[0];
        if (key != key_prev) {
            struct nc_rt_stats ref;
            double ref0 = flux(&r, s, range, 0, -1, &f, &ref), ref1 = flux(&r, s, next_range, 0, -1, &f, &ref);
            double pop = (now / prev) / (ref1 / ref0) - 1;
            worst = fmax(worst, fabs(pop));
            if (next_range <= near_m)
                worst_near = fmax(worst_near, fabs(pop));
            if (getenv("NC_POP_DEBUG"))
                printf("  %.0f m: level %d, %zu rocks from %.3g m: pop %+.3f %%\n", next_range, st.lod_level[0],
                       st.boulders_traced[0], st.boulder_min_m[0], 100 * pop);
            changes++;
        }
        prev = now;
        key_prev = key;
        range = next_range;
    }
    printf("%s: %d changes from %.0f km to 1.4 km in 5 %% range steps; the largest pop %.3f %% (tolerance %.2f %%), "
           "%.3f %% from %.0f km in (tolerance %.2f %%)\n", what, changes, from_m / 1000, 100 * worst, 100 * tol,
           100 * worst_near, near_m / 1000, 100 * tol_near);
    CHECK(changes >= expect_changes, "%s: only %d changes", what, changes);
    CHECK(worst < tol && worst_near < tol_near, "%s: a change popped the brightness by %.3f %% (%.3f %% near)", what,
          100 * worst, 100 * worst_near);
    nc_frame_free(&f);
    nc_renderer_free(&r);
}

int main(void)
{
    /* the default scene's asteroid at 20 * 4^6 triangles, 512x512 pixels
     * over 26 deg: the whole body stays in the frame down to 1.4 km (a
     * clipped body's flux jumps with the framing, not the detail) */
    const char *sets[] = {"camera.width_px=512", "camera.height_px=512", "camera.focal_length_m=0.006",
                          "bodies.0.shape.subdivisions=6"};
    struct nc_scene s;
    /* the mesh at 20 * 4^7 triangles: levels switch twice on the way in */
    const char *fine[] = {sets[0], sets[1], sets[2], "bodies.0.shape.subdivisions=7"};
    nc_test_scene(nc_default_scene_yaml, fine, 4, &s);
    sweep("mesh levels (lod_error_px 0.25)", &s, 30000, 0.25, 0, 0.003, 30000, 0.003, 2);
    nc_scene_free(&s);
    /* the same with the Bennu boulders from 0.5 m, cut at 1 px and folded */
    const char *rocks[] = {sets[0], sets[1], sets[2], sets[3], "bodies.0.boulders={preset: bennu, min_diameter_m: 0.5}"};
    nc_test_scene(nc_default_scene_yaml, rocks, 5, &s);
    /* Far out, each step brings in tens of rocks about a pixel across on a
     * body tens of pixels wide: the pops are larger there. */
    sweep("boulder cut (boulder_min_px 1, folded)", &s, 12000, 0, 1, 0.01, 6000, 0.006, 30);
    nc_scene_free(&s);
    return nc_test_end();
}
