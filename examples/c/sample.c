/* The C API in one program: open a baked table, look f_r up, importance-sample it.
 *
 * Build against the source tree (after `cargo build --release -p clothbake-capi`):
 *   cc -I crates/clothbake-capi/include examples/c/sample.c \
 *      target/release/libclothbake_capi.a -lpthread -ldl -lm -o sample
 * or against an installed copy (`cargo xtask install-capi PREFIX`, docs/reference/loader.md):
 *   cc examples/c/sample.c $(pkg-config --cflags --libs clothbake) -o sample
 * Run: ./sample twill.exr
 */
#include <stdio.h>

#include "clothbake.h"

int main(int argc, char **argv) {
    const char *path = argc > 1 ? argv[1] : "twill.exr";
    clothbake_brdf *b = clothbake_open(path, 0); /* | CLOTHBAKE_F32, CLOTHBAKE_RECIPROCAL, CLOTHBAKE_NO_SAMPLING */
    if (!b) {
        fprintf(stderr, "%s\n", clothbake_last_error());
        return 1;
    }
    /* Unit vectors in the cloth's frame: +Z normal, +X weft, +Y warp; wi toward the light. */
    float wi[3] = {0.3f, 0.1f, 0.9486833f}, wo[3] = {-0.4f, 0.2f, 0.8944272f}, f[3];
    if (clothbake_eval(b, wi, wo, f) != 0) {
        fprintf(stderr, "%s\n", clothbake_last_error());
        clothbake_close(b);
        return 1;
    }
    printf("f_r %.9g %.9g %.9g 1/sr\n", f[0], f[1], f[2]);
    float s_wi[3], weight[3], pdf;
    if (clothbake_sample(b, wo, 0.25f, 0.75f, s_wi, weight, &pdf) != 0) {
        fprintf(stderr, "%s\n", clothbake_last_error());
        clothbake_close(b);
        return 1;
    }
    printf("sampled wi %.9g %.9g %.9g weight %.9g %.9g %.9g pdf %.9g 1/sr\n", s_wi[0], s_wi[1],
           s_wi[2], weight[0], weight[1], weight[2], pdf);
    clothbake_close(b);
    return 0;
}
