/* test_rng.c - the batched Philox (rng.c) is bit-identical to Random123's
 * philox4x32 for every word, across batch boundaries and keys. */
#include <stdio.h>
#include <stdlib.h>

#include "camera/rng.h"
#include "testutil.h"

int main(void)
{
    const uint64_t seeds[] = {0, 1, 42, 0xdeadbeefcafef00dull};
    const uint64_t frames[] = {0, 7, 1ull << 33};
    enum { N = 1000 };
    static uint32_t w0[N], w1[N], w2[N], w3[N];
    uint32_t *const w[4] = {w0, w1, w2, w3};
    long bad = 0, n = 0;
    for (int s = 0; s < 4; s++)
        for (int f = 0; f < 3; f++)
            for (int st = 1; st <= 3; st++) {
                nc_rng_words(seeds[s], (enum nc_rng_stream)st, frames[f], 12345u, 2u, N, w);
                for (int i = 0; i < N; i++) {
                    philox4x32_key_t k = {{(uint32_t)seeds[s], (uint32_t)(seeds[s] >> 32)}};
                    philox4x32_ctr_t c = {{12345u + (uint32_t)i, (uint32_t)frames[f],
                                           (uint32_t)(frames[f] >> 32) ^ ((uint32_t)st << 28), 2u}};
                    philox4x32_ctr_t r = philox4x32(c, k);
                    for (int j = 0; j < 4; j++, n++)
                        bad += r.v[j] != w[j][i];
                }
            }
    printf("batched Philox4x32-10: %ld of %ld words differ from Random123\n", bad, n);
    CHECK(bad == 0, "%ld words differ", bad);
    return nc_test_end();
}
