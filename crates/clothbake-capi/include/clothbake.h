/* clothbake.h: the C API of the clothbake loader (crate clothbake-capi).
 *
 * Load a BRDF table baked by `clothbake`, look it up with quadrilinear interpolation and
 * importance-sample it. Link with libclothbake_capi.a (plus -lpthread -ldl -lm on Linux) or
 * libclothbake_capi.so. Guide: docs/reference/loader.md.
 *
 * Directions are unit vectors in the cloth's local frame: +Z the normal, +X the weft, +Y the
 * warp; wi points toward the light, wo toward the eye. Values are f_r in 1/sr, RGB. Directions
 * with z <= 1e-9 are below the horizon and give 0.
 *
 * Errors: functions return -1 (or NULL) and keep a message for clothbake_last_error(), per
 * thread. Nothing aborts or unwinds into the caller. A handle may be used by many threads at
 * once (every function but clothbake_close only reads it).
 */
#ifndef CLOTHBAKE_H
#define CLOTHBAKE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Flags of clothbake_open, combined with |. */
#define CLOTHBAKE_F32 1u         /* hold values as f32 even if the file stores half floats */
#define CLOTHBAKE_RECIPROCAL 2u  /* symmetrise: 0.5 (f(wi, wo) + f(wo, wi)) */
#define CLOTHBAKE_NO_SAMPLING 4u /* skip the sampling CDFs (4 bytes a cell) */
#define CLOTHBAKE_NO_POINT_LEVEL 8u /* no point level: the crossing cells answer every footprint under a period */

/* An open table (opaque). */
typedef struct ClothbakeBrdf clothbake_brdf;

/* Opens a table (.exr or .bin, told apart by content). NULL on error. */
clothbake_brdf *clothbake_open(const char *path, uint32_t flags);

/* Closes a table; NULL is ignored. */
void clothbake_close(clothbake_brdf *brdf);

/* The grid {n_theta_i, n_phi_i, n_theta_o, n_phi_o} into out[4]. 0, or -1 on error. */
int clothbake_grid(const clothbake_brdf *brdf, uint32_t *out);

/* f_r(wi, wo) into out[3] (RGB, 1/sr). 0, or -1 on error. */
int clothbake_eval(const clothbake_brdf *brdf, const float *wi, const float *wo, float *out);

/* f_r at point (u, v) of the weave period (fractions, wrapped) through a footprint of side
 * `width` periods (0: the point; >= 1: clothbake_eval) into out[3], and the share of the
 * footprint in which the eye meets yarn into *coverage (unless NULL), at the footprint's level
 * of detail (docs/science/spatial.md): a table baked with --spatial (one bounce) carries its yarns and
 * traces them under a crossing cell (unless opened with CLOTHBAKE_NO_POINT_LEVEL), shows its
 * crossing cells from two cells wide, and the average from a period; another answers
 * clothbake_eval and coverage 1. 0, or -1 on error. */
int clothbake_eval_at(const clothbake_brdf *brdf, const float *wi, const float *wo, double u,
                      double v, double width, float *out, float *coverage);

/* f_r at angles in degrees (theta from +Z, phi from +X toward +Y) into out[3]. */
int clothbake_eval_deg(const clothbake_brdf *brdf, float theta_i, float phi_i, float theta_o,
                       float phi_o, float *out);

/* n lookups: wi, wo, out hold 3 n floats each (x y z / R G B per item). */
int clothbake_eval_batch(const clothbake_brdf *brdf, const float *wi, const float *wo, size_t n,
                         float *out);

/* Samples wi[3] for wo from u1, u2 in [0, 1); weight[3] = f_r cos(theta_i) / pdf; pdf per unit
 * solid angle (0: no sample, e.g. wo below the horizon). 0, or -1 on error. */
int clothbake_sample(const clothbake_brdf *brdf, const float *wo, float u1, float u2, float *wi,
                     float *weight, float *pdf);

/* The density with which clothbake_sample draws wi for wo, into *pdf. 0, or -1 on error. */
int clothbake_pdf(const clothbake_brdf *brdf, const float *wo, const float *wi, float *pdf);

/* This thread's last error message, or NULL. Valid until the next failing call; do not free. */
const char *clothbake_last_error(void);

#ifdef __cplusplus
}
#endif

#endif /* CLOTHBAKE_H */
