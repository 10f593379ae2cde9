/* test_tile_list.c - rendering a sample of a frame (render.h), what pilots
 * draw: nc_render_tile_list renders the listed tiles as the whole frame has
 * them and leaves the others as they were; the two checkerboard halves of 4
 * x 4 blocks, one after the other, give the whole tiles; the plane `one` of
 * a 4-sample render is, with hard shadows and no bounce, bit for bit the
 * frame of one sample a pixel drawn as the first of 4 passes, and with soft
 * shadows and a bounce (a bright boulder over bright ground) a one-sample
 * estimate of the same mean, bounce light included. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "testutil.h"

/* A boulder over the ground, bright: light bounces between them. */
static const char pair_yaml[] =
    "bodies:\n"
    "  - name: ground\n"
    "    shape: {type: sphere, radius_m: 1000}\n"
    "    material: {model: lambert, A: 0.9}\n"
    "  - name: boulder\n"
    "    shape: {type: sphere, radius_m: 80}\n"
    "    material: {model: lambert, A: 0.9}\n"
    "    position_m: [0, 0, -1120]\n"
    "sun: {direction: [0.25, 0.1, -1], distance_au: 0.05}\n"
    "render: {samples_per_pixel: 4, soft_shadows: true, bounces: 1}\n"
    "camera: {width_px: 100, height_px: 90, fx_px: 130, fy_px: 130, position_m: [-900, 300, -1700],\n"
    "         look_at_m: [40, 0, -990], up: [0, 0, -1]}\n";

static void fail_if(int rc)
{
    if (rc < 0) {
        fprintf(stderr, "render: %s\n", nc_errmsg());
        exit(2);
    }
}

static size_t differ(const float *a, const float *b, size_t n)
{
    size_t d = 0;
    for (size_t i = 0; i < n; i++)
        d += memcmp(&a[i], &b[i], sizeof(float)) != 0;
    return d;
}

int main(void)
{
    const char *sets[] = {"render.samples_per_pixel=4", "camera.width_px=100", "camera.height_px=90"};
    struct nc_scene s;
    nc_test_scene(nc_test_asteroid_yaml, sets, 3, &s);
    const int W = s.camera.width_px, H = s.camera.height_px, cols = (W + NC_TILE - 1) / NC_TILE;
    const size_t n = (size_t)W * (size_t)H;
    struct nc_renderer r;
    fail_if(nc_renderer_init(&r, &s, 2));
    struct nc_frame full, part, halves;
    fail_if(nc_frame_alloc(&full, W, H));
    fail_if(nc_frame_alloc(&part, W, H));
    fail_if(nc_frame_alloc(&halves, W, H));
    fail_if(nc_render_frame(&r, &s, &full));

    /* Tiles 2 of every 3 (the frame's edge tiles, partly outside it, among them). */
    int tiles[64], nt = 0;
    for (int t = 0; t < cols * nc_render_tile_rows(&s); t++)
        if (t % 3)
            tiles[nt++] = t;
    for (size_t i = 0; i < n; i++)
        part.radiance[i] = halves.radiance[i] = -1.0f;
    fail_if(nc_render_tile_list(&r, &s, &part, tiles, nt, 0, NULL));
    fail_if(nc_render_tile_list(&r, &s, &halves, tiles, nt, 1, NULL));
    size_t wrong = 0, untouched = 0, half_done = 0, lit = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t o = (size_t)y * (size_t)W + (size_t)x;
            const int listed = (y / NC_TILE * cols + x / NC_TILE) % 3 != 0;
            const int even = (x % NC_TILE / 4 + y % NC_TILE / 4) % 2 == 0;
            wrong += listed ? memcmp(&part.radiance[o], &full.radiance[o], sizeof(float)) != 0
                            : part.radiance[o] != -1.0f;
            untouched += !listed;
            half_done += listed && !even && halves.radiance[o] == -1.0f;
            wrong += listed && even && memcmp(&halves.radiance[o], &full.radiance[o], sizeof(float)) != 0;
            lit += listed && full.radiance[o] > 0;
        }
    fail_if(nc_render_tile_list(&r, &s, &halves, tiles, nt, 2, NULL));
    size_t whole = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t o = (size_t)y * (size_t)W + (size_t)x;
            if ((y / NC_TILE * cols + x / NC_TILE) % 3 != 0)
                whole += memcmp(&halves.radiance[o], &full.radiance[o], sizeof(float)) != 0;
        }
    printf("tile list: %zu lit pixels in %d tiles, %zu outside left as they were, %zu wrong; "
           "first half left %zu of the odd blocks' pixels alone; both halves differ from the frame in %zu\n",
           lit, nt, untouched, wrong, half_done, whole);
    CHECK(lit > 1000 && untouched > 1000, "too few pixels: %zu lit, %zu outside", lit, untouched);
    CHECK(wrong == 0 && whole == 0, "%zu, %zu pixels unlike the whole frame's", wrong, whole);
    CHECK(half_done > 1000, "the first checkerboard half should leave the odd blocks alone (%zu)", half_done);
    CHECK(nc_render_tile_list(&r, &s, &part, tiles, nt, 3, NULL) < 0, "blocks 3 should be refused");
    tiles[0] = cols * nc_render_tile_rows(&s);
    CHECK(nc_render_tile_list(&r, &s, &part, tiles, 1, 0, NULL) < 0, "a tile past the frame should be refused");

    /* The plane `one`: hard shadows, no bounce. */
    const struct nc_sample_pass first = {0, 4, 4};
    fail_if(!(full.one = malloc(n * sizeof *full.one)) ? -1 : 0);
    fail_if(nc_render_frame(&r, &s, &full));
    fail_if(nc_render_rows_timed(&r, &s, &part, 0, nc_render_tile_rows(&s), NULL, &first));
    size_t one_differ = differ(full.one, part.radiance, n), one_unlike_mean = differ(full.one, full.radiance, n);
    printf("plane one: unlike the first of 4 passes in %zu pixels, unlike the 4-sample mean in %zu\n", one_differ,
           one_unlike_mean);
    CHECK(one_differ == 0, "%zu pixels", one_differ);
    CHECK(one_unlike_mean > 100, "one sample should differ from the mean of 4 at edges (%zu)", one_unlike_mean);

    /* With soft shadows and a bounce: the sample's Sun-disk point and path
     * are its own, so only the means over many pixels agree. */
    struct nc_scene soft;
    struct nc_renderer rs;
    nc_test_scene(pair_yaml, NULL, 0, &soft);
    fail_if(nc_renderer_init(&rs, &soft, 2));
    fail_if(!(full.direct = malloc(n * sizeof *full.direct)) ? -1 : 0);
    fail_if(nc_render_frame(&rs, &soft, &full));
    nc_renderer_free(&rs);
    nc_scene_free(&soft);
    double sum_one = 0, sum_mean = 0, sum_dir = 0;
    for (size_t i = 0; i < n; i++) {
        sum_one += full.one[i];
        sum_mean += full.radiance[i];
        sum_dir += full.direct[i];
    }
    const double bounce = 1 - sum_dir / sum_mean, off = sum_one / sum_mean - 1;
    printf("soft shadows and a bounce: plane one's mean %+.2e of the 4-sample frame's, whose bounce light is %.2e "
           "of it\n",
           off, bounce);
    CHECK(bounce > 1e-3 && fabs(off) < 0.25 * bounce, "one-sample mean off by %g, bounce light %g", off, bounce);

    nc_frame_free(&full);
    nc_frame_free(&part);
    nc_frame_free(&halves);
    nc_renderer_free(&r);
    nc_scene_free(&s);
    return nc_test_end();
}
