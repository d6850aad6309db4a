/* ThunderLoom's tl_shade (the Irawan cloth model) on the shading points of a clothbake picture,
 * for the close-up comparison of `cargo xtask figures yarns --thunderloom DIR`. ThunderLoom is
 * not part of clothbake: fetch its single header src/thunderloom.h (github.com/vidarn/ThunderLoom,
 * commit 62e6d750, v0.97.0) into DIR; the xtask compiles this file beside it with
 *   g++ -x c++ -O2 -o DIR/tl_shade thunderloom_shade.c -I DIR
 * and runs it. Input on stdin, little-endian: u32 W, u32 H, u32 T; W*H u8 warp_above
 * (pattern[x + y*W], x the warp thread, y the weft thread); W*H u8 yarn_type (1..T, the thread
 * on top's colour); T x 3 f32 colours; u32 N; N records of 8 f32 (u, v in period fractions,
 * wi xyz, wo xyz in the cloth frame: +x along u, the weft; +z the normal). Output on stdout: N x 3
 * f32, tl_shade's colour (albedo times cos(theta_i) for the diffuse part: the thesis's intensity
 * I for unit light). Yarn parameters are the library's defaults (tl_default_yarn_type). */
#define TL_NO_FILES
#define TL_NO_TEXTURE_CALLBACKS
#define TL_THUNDERLOOM_IMPLEMENTATION
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <ctype.h>
#include <math.h>
#include "thunderloom.h"

static void need(size_t got, size_t want) {
    if (got != want) {
        fprintf(stderr, "tl_shade: short input\n");
        exit(2);
    }
}

int main(void) {
    uint32_t w, h, t, n;
    need(fread(&w, 4, 1, stdin), 1);
    need(fread(&h, 4, 1, stdin), 1);
    need(fread(&t, 4, 1, stdin), 1);
    if (w == 0 || h == 0 || w > 4096 || h > 4096 || t == 0 || t > 250) {
        fprintf(stderr, "tl_shade: bad pattern size\n");
        return 2;
    }
    uint8_t *above = (uint8_t *)malloc(w * h), *type = (uint8_t *)malloc(w * h);
    tlColor *colors = (tlColor *)malloc(sizeof(tlColor) * t);
    need(fread(above, 1, w * h, stdin), w * h);
    need(fread(type, 1, w * h, stdin), w * h);
    need(fread(colors, sizeof(tlColor), t, stdin), t);
    need(fread(&n, 4, 1, stdin), 1);
    tlWeaveParameters *p = tl_weave_pattern_from_data(above, type, t, colors, w, h);
    p->uscale = 1.f; p->vscale = 1.f; p->uvrotation = 0.f;
    p->intensity_fineness = 0.f; p->realworld_uv = 0;
    tl_prepare(p);
    float rec[8];
    for (uint32_t k = 0; k < n; k++) {
        need(fread(rec, 4, 8, stdin), 8);
        tlIntersectionData d;
        d.uv_x = rec[0]; d.uv_y = rec[1];
        d.wi_x = rec[2]; d.wi_y = rec[3]; d.wi_z = rec[4];
        d.wo_x = rec[5]; d.wo_y = rec[6]; d.wo_z = rec[7];
        d.context = NULL;
        tlColor c = tl_shade(d, p);
        fwrite(&c, sizeof c, 1, stdout);
    }
    tl_free_weave_parameters(p);
    free(p); free(above); free(type); free(colors);
    return 0;
}
