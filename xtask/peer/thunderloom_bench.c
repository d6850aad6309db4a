/* Timing harness for ThunderLoom's tl_shade (the Irawan cloth model) on a 2/1 twill, for the
 * side-by-side run in docs/results/performance.md. ThunderLoom is not part of clothbake: fetch its
 * single header src/thunderloom.h (github.com/vidarn/ThunderLoom, commit 62e6d750, v0.97.0)
 * beside this file, then
 *   gcc -x c++ -O3 -march=native -o tl_bench thunderloom_bench.c -lm -lstdc++
 *   taskset -c 1 ./tl_bench
 * Pattern rows [1,1,0] [0,1,1] [1,0,1] (each warp over 2 wefts, under 1), one yarn type with
 * the library's defaults (tl_default_yarn_type: staple-yarn specular, specular on, no noise),
 * uscale = vscale = 1; a pool of 65536 pairs uniform in solid angle (uv uniform in the period),
 * 7 rounds of 65536 calls timed with the thread's CPU clock, median printed; "coherent": the
 * first 64 pairs cycled. */
#define TL_NO_FILES
#define TL_NO_TEXTURE_CALLBACKS
#define TL_THUNDERLOOM_IMPLEMENTATION
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <ctype.h>
#include <math.h>
#include <time.h>
/* NOTE: thunderloom.h only compiles as C++ (struct tags used as type names,
   a function-local static with a non-constant initializer at line ~987), so
   this file is compiled with `gcc -x c++`. The harness itself is plain C. */
#include "thunderloom.h"

#define POOL (1u << 16)
#define COHERENT 64
#define ROUNDS 7

static uint64_t sm_state = 0x243F6A8885A308D3ull;
static uint64_t splitmix64(void) {
    uint64_t z = (sm_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static float rnd01(void) { return (float)(splitmix64() >> 40) * (1.0f / 16777216.0f); } /* [0,1) */

/* uniform in solid angle over z>0: z ~ U(0,1], phi ~ U[0,2pi) */
static void hemi(float *x, float *y, float *z) {
    float zz = 1.0f - rnd01();            /* (0,1] */
    float phi = 2.0f * (float)M_PI * rnd01();
    float r = sqrtf(fmaxf(0.f, 1.f - zz * zz));
    *x = r * cosf(phi); *y = r * sinf(phi); *z = zz;
}

static double now_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e9 + ts.tv_nsec;
}

static int cmpd(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

volatile double g_sink;

static double run_round(const tlIntersectionData *pool, uint32_t mask, uint32_t ncalls,
                        const tlWeaveParameters *p) {
    double acc = 0.0;
    double t0 = now_ns();
    for (uint32_t i = 0; i < ncalls; i++) {
        tlColor c = tl_shade(pool[i & mask], p);
        acc += (double)c.r + (double)c.g + (double)c.b;
    }
    double t1 = now_ns();
    g_sink = g_sink + acc;
    return (t1 - t0) / ncalls;
}

static void bench(const char *name, const tlIntersectionData *pool, uint32_t mask,
                  const tlWeaveParameters *p) {
    double t[ROUNDS];
    uint32_t ncalls = POOL;
    run_round(pool, mask, ncalls, p); /* warm-up */
    run_round(pool, mask, ncalls, p);
    printf("%s (%u distinct pairs, %u calls/round):", name, mask + 1, ncalls);
    for (int r = 0; r < ROUNDS; r++) {
        t[r] = run_round(pool, mask, ncalls, p);
        printf(" %.1f", t[r]);
    }
    qsort(t, ROUNDS, sizeof t[0], cmpd);
    printf("  ns/call -> median %.1f ns/call\n", t[ROUNDS / 2]);
}

int main(void) {
    /* 2/1 twill, pattern[x + y*W], rows y=0..2: [1,1,0],[0,1,1],[1,0,1] */
    uint8_t warp_above[9] = {1, 1, 0,
                             0, 1, 1,
                             1, 0, 1};
    uint8_t yarn_type[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
    tlColor colors[1] = {{0.3f, 0.3f, 0.3f}}; /* = library default yarn colour */
    tlWeaveParameters *p = tl_weave_pattern_from_data(warp_above, yarn_type, 1, colors, 3, 3);
    /* fabric params are calloc'ed to 0 by tl_weave_pattern_from_data; set as the
       api_demo / Mitsuba frontend do */
    p->uscale = 1.f; p->vscale = 1.f; p->uvrotation = 0.f;
    p->intensity_fineness = 0.f; p->realworld_uv = 0;
    tl_prepare(p);

    tlIntersectionData *pool = (tlIntersectionData *)malloc(sizeof(tlIntersectionData) * POOL);
    for (uint32_t i = 0; i < POOL; i++) {
        tlIntersectionData *d = &pool[i];
        d->uv_x = rnd01(); d->uv_y = rnd01();
        hemi(&d->wi_x, &d->wi_y, &d->wi_z);
        hemi(&d->wo_x, &d->wo_y, &d->wo_z);
        d->context = NULL;
    }

    /* sanity statistics (untimed) */
    uint32_t nonfinite = 0, hit = 0, spec_nz = 0, warp = 0;
    double mean = 0;
    for (uint32_t i = 0; i < POOL; i++) {
        tlPatternData pd = tl_get_pattern_data(pool[i], p);
        tlColor s = tl_eval_specular(pool[i], pd, p);
        tlColor c = tl_shade(pool[i], p);
        if (!isfinite(c.r) || !isfinite(c.g) || !isfinite(c.b)) nonfinite++;
        else mean += c.r + c.g + c.b;
        if (pd.yarn_hit) hit++;
        if (pd.yarn_hit && pd.warp_above) warp++;
        if (s.r > 0.f) spec_nz++;
    }
    printf("pool sanity: yarn_hit %.1f%%, warp on top %.1f%%, specular>0 %.1f%%, non-finite %u, mean(r+g+b) %.5f\n",
           100.0 * hit / POOL, 100.0 * warp / POOL, 100.0 * spec_nz / POOL, nonfinite, mean / (POOL - nonfinite));

    bench("random  ", pool, POOL - 1, p);
    bench("coherent", pool, COHERENT - 1, p);
    printf("(sink %g)\n", (double)g_sink);
    tl_free_weave_parameters(p);
    free(p);
    free(pool);
    return 0;
}
