/* Checks the C API against values computed by the Rust loader (tests/tests/capi.rs writes them).
 *
 * usage: lookup TABLE CASES
 * CASES has one case per line:
 *   G nti npi nto npo                      the grid
 *   E wix wiy wiz wox woy woz r g b        clothbake_eval (and, all together, clothbake_eval_batch)
 *   D ti pi to po r g b                    clothbake_eval_deg
 *   S wox woy woz u1 u2 wix wiy wiz r g b pdf   clothbake_sample
 *   P wox woy woz wix wiy wiz pdf          clothbake_pdf
 *   A wix wiy wiz wox woy woz u v width r g b coverage   clothbake_eval_at
 * Floats are printed with 9 significant digits, so they round-trip exactly: the C results
 * must equal the Rust ones bit for bit. Exit status 0 when every check passes.
 */
#include "clothbake.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_EVAL 4096

static int failures = 0;

static void check(int ok, const char *what, int line) {
    if (!ok) {
        fprintf(stderr, "FAIL line %d: %s\n", line, what);
        failures++;
    }
}

static int same3(const float *a, const float *b) {
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: lookup TABLE CASES\n");
        return 2;
    }

    /* Errors: a clear message, no crash. */
    if (clothbake_open("/no/such/folder/missing.exr", 0) != NULL) {
        fprintf(stderr, "FAIL: opening a missing file succeeded\n");
        return 1;
    }
    const char *e = clothbake_last_error();
    check(e != NULL && strstr(e, "missing.exr") != NULL, "the error names the missing file", 0);
    float out[3];
    float up[3] = {0.0f, 0.0f, 1.0f};
    check(clothbake_eval(NULL, up, up, out) == -1, "eval on NULL fails", 0);
    e = clothbake_last_error();
    check(e != NULL && strstr(e, "NULL") != NULL, "the error says NULL", 0);
    check(clothbake_open(argv[1], 1024u) == NULL, "unknown flags are refused", 0);

    clothbake_brdf *b = clothbake_open(argv[1], 0);
    if (b == NULL) {
        fprintf(stderr, "FAIL: cannot open %s: %s\n", argv[1], clothbake_last_error());
        return 1;
    }
    check(clothbake_eval(b, NULL, up, out) == -1, "eval with wi NULL fails", 0);

    FILE *f = fopen(argv[2], "r");
    if (f == NULL) {
        fprintf(stderr, "cannot read %s\n", argv[2]);
        return 2;
    }
    static float wis[3 * MAX_EVAL], wos[3 * MAX_EVAL], want[3 * MAX_EVAL], got[3 * MAX_EVAL];
    size_t n_eval = 0;
    int counts[6] = {0, 0, 0, 0, 0, 0};
    char tag;
    int line = 0;
    while (fscanf(f, " %c", &tag) == 1) {
        line++;
        if (tag == 'G') {
            unsigned g[4];
            uint32_t have[4];
            if (fscanf(f, "%u %u %u %u", &g[0], &g[1], &g[2], &g[3]) != 4) break;
            check(clothbake_grid(b, have) == 0, "grid", line);
            check(have[0] == g[0] && have[1] == g[1] && have[2] == g[2] && have[3] == g[3],
                  "grid matches", line);
            counts[0]++;
        } else if (tag == 'E') {
            float *wi = &wis[3 * n_eval], *wo = &wos[3 * n_eval], *w = &want[3 * n_eval];
            if (fscanf(f, "%f %f %f %f %f %f %f %f %f", &wi[0], &wi[1], &wi[2], &wo[0], &wo[1],
                       &wo[2], &w[0], &w[1], &w[2]) != 9 || n_eval + 1 >= MAX_EVAL)
                break;
            check(clothbake_eval(b, wi, wo, out) == 0, "eval returns 0", line);
            check(same3(out, w), "eval equals the Rust loader", line);
            n_eval++;
            counts[1]++;
        } else if (tag == 'D') {
            float a[4], w[3];
            if (fscanf(f, "%f %f %f %f %f %f %f", &a[0], &a[1], &a[2], &a[3], &w[0], &w[1], &w[2]) != 7)
                break;
            check(clothbake_eval_deg(b, a[0], a[1], a[2], a[3], out) == 0, "eval_deg returns 0", line);
            check(same3(out, w), "eval_deg equals the Rust loader", line);
            counts[2]++;
        } else if (tag == 'S') {
            float wo[3], u1, u2, w_wi[3], w_weight[3], w_pdf, wi[3], weight[3], pdf;
            if (fscanf(f, "%f %f %f %f %f %f %f %f %f %f %f %f", &wo[0], &wo[1], &wo[2], &u1, &u2,
                       &w_wi[0], &w_wi[1], &w_wi[2], &w_weight[0], &w_weight[1], &w_weight[2],
                       &w_pdf) != 12)
                break;
            check(clothbake_sample(b, wo, u1, u2, wi, weight, &pdf) == 0, "sample returns 0", line);
            check(same3(wi, w_wi) && same3(weight, w_weight) && pdf == w_pdf,
                  "sample equals the Rust loader", line);
            counts[3]++;
        } else if (tag == 'P') {
            float wo[3], wi[3], w_pdf, pdf;
            if (fscanf(f, "%f %f %f %f %f %f %f", &wo[0], &wo[1], &wo[2], &wi[0], &wi[1], &wi[2],
                       &w_pdf) != 7)
                break;
            check(clothbake_pdf(b, wo, wi, &pdf) == 0, "pdf returns 0", line);
            check(pdf == w_pdf, "pdf equals the Rust loader", line);
            counts[4]++;
        } else if (tag == 'A') {
            float wi[3], wo[3], w[3], w_cov, cov;
            double u, v, width;
            if (fscanf(f, "%f %f %f %f %f %f %lf %lf %lf %f %f %f %f", &wi[0], &wi[1], &wi[2],
                       &wo[0], &wo[1], &wo[2], &u, &v, &width, &w[0], &w[1], &w[2], &w_cov) != 13)
                break;
            check(clothbake_eval_at(b, wi, wo, u, v, width, out, &cov) == 0, "eval_at returns 0",
                  line);
            check(same3(out, w) && cov == w_cov, "eval_at equals the Rust loader", line);
            check(clothbake_eval_at(b, wi, wo, u, v, -1.0, out, NULL) == -1,
                  "eval_at with a negative width fails", line);
            counts[5]++;
        } else {
            fprintf(stderr, "bad tag %c on line %d\n", tag, line);
            return 2;
        }
    }
    fclose(f);

    check(clothbake_eval_batch(b, wis, wos, n_eval, got) == 0, "eval_batch returns 0", 0);
    for (size_t k = 0; k < n_eval; k++) {
        check(same3(&got[3 * k], &want[3 * k]), "eval_batch equals the Rust loader", (int)k);
    }
    check(clothbake_eval_batch(b, NULL, wos, n_eval, got) == -1, "eval_batch with NULL fails", 0);
    clothbake_close(b);

    printf("checked %d grid, %d eval (and batch), %d eval_deg, %d sample, %d pdf, %d eval_at cases: "
           "%d failures\n",
           counts[0], counts[1], counts[2], counts[3], counts[4], counts[5], failures);
    return failures == 0 ? 0 : 1;
}
