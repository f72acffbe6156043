/* C ABI of the mitsuba-birefringent Rust core (static library libbirefringent.a).
 *
 * Kept by hand next to src/ffi.rs; tests/c_abi.rs compiles and runs a C program against this
 * header and checks every struct's size and the results against the Rust API.
 *
 * Conventions: local shading frame (z = surface normal towards the exterior; a bulk crystal
 * fills z < 0; a plate has the exterior medium above and the exit medium below). Complex
 * indices are n + i kappa with kappa >= 0 (the core's time convention exp(-i w t)). Mueller
 * matrices are row-major 4x4 in Mitsuba's convention (already converted), power fractions.
 * A Stokes frame is given by its x axis; y = (propagation direction) x (x axis).
 * No function unwinds or aborts: errors are returned as codes with a NUL-terminated message
 * naming the parameter (truncated to message_len bytes; message may be NULL).
 */
#ifndef BIREFRINGENT_H
#define BIREFRINGENT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define BFR_OK 0       /* success */
#define BFR_INVALID 1  /* invalid input; the message names the parameter */
#define BFR_INTERNAL 2 /* a bug (caught panic or non-finite result) */

/* Flags of the plate queries. */
#define BFR_WANT_REFLECTION 1
#define BFR_WANT_TRANSMISSION 2
#define BFR_INTENSITY_ONLY 4 /* only mueller[0] (M00) is computed; the rest is zero */
#define BFR_ABSORBING_EXIT 8 /* the exit medium absorbs what enters it: no transmission lobe,
                                no light from below (a film on a black substrate) */

typedef struct bfr_complex {
    double re, im;
} bfr_complex;

/* Principal indices of a uniaxial material. */
typedef struct bfr_material_desc {
    const char *material; /* a named crystal (see `birefringence` docs), or NULL */
    bfr_complex eta_o;    /* used when material is NULL */
    bfr_complex eta_e;    /* used when material is NULL */
    double kappa_o;       /* extinction added to the ordinary index (>= 0) */
    double kappa_e;       /* extinction added to the extraordinary index (>= 0) */
} bfr_material_desc;

/* Opaque, immutable, thread-safe: the indices as functions of wavelength. */
typedef struct bfr_material bfr_material;

/* Per-query geometry (may vary over a surface, e.g. from textures). */
typedef struct bfr_geometry {
    double ext_ior;        /* real index of the exterior (z > 0) */
    double exit_ior;       /* plate only: real index below the plate */
    double optic_axis[3];  /* local frame, any non-zero length */
    double thickness_nm;   /* plate only, >= 0 */
    double birefringence;  /* added to Re(eta_e) (photoelastic stress); 0 = none */
} bfr_geometry;

/* Transport modes (Mitsuba's TransportMode). */
#define BFR_RADIANCE 0
#define BFR_IMPORTANCE 1

/* One lobe as a path tracer samples it at a surface seen from wi (Mitsuba's si.wi, local).
 * Physically the light arrives along -wo_hat and leaves along wi_hat, where
 * (wo_hat, wi_hat) = (wo, wi) in Radiance mode and (wi, wo) in Importance mode. */
typedef struct bfr_path_lobe {
    int32_t exists;          /* 1 if this lobe carries light */
    int32_t component;       /* crystal: 0 reflection, 1 ordinary, 2 extraordinary transmission;
                                plate: 0 reflection, 1 transmission */
    double wo[3];            /* Mitsuba's wo for this lobe (unit, local) */
    double in_stokes_x[3];   /* x axis of the Stokes frame of the light arriving along -wo_hat */
    double out_stokes_x[3];  /* x axis of the Stokes frame of the light leaving along wi_hat */
    double mueller[16];      /* in -> out, Mitsuba's convention, power fractions; in Radiance
                                mode already scaled by the radiance factor (n_in / n_out)^2 */
    double weight;           /* mueller[0]: unpolarised throughput, for lobe selection */
    double eta;              /* Mitsuba's bs.eta: ray index on the wo side over the wi side */
} bfr_path_lobe;

/* Bulk crystal: up to 6 lobes (seen from inside, each of the o and e waves that can travel
 * along wi has a reflected o, a reflected e and a transmitted lobe; from outside:
 * reflection, o and e transmission). Lobes are packed at the front of out[] (a wave that
 * does not exist, e.g. under total internal reflection, leaves no gap), so the same index
 * may hold different lobes at different wavelengths; match them by component and direction.
 * Two lobes may share a component (reflections inside the crystal). */
#define BFR_CRYSTAL_LOBES 6

/* Creates a material; NULL on error (message set). On success message holds a warning, empty
 * if none: a named crystal whose cited data do not cover 360-830 nm (where Mitsuba samples)
 * and whose fit is extrapolated there. Free with bfr_material_free. */
bfr_material *bfr_material_new(const bfr_material_desc *desc, char *message, size_t message_len);
void bfr_material_free(bfr_material *material);

/* Indices at a wavelength (nm). */
int32_t bfr_material_indices(const bfr_material *material, double wavelength_nm,
                             bfr_complex *eta_o, bfr_complex *eta_e);

/* Bulk crystal surface (crystal below, z < 0): the lobes seen from wi. transport: BFR_RADIANCE
 * or BFR_IMPORTANCE. Unused entries of out[] have exists = 0. */
int32_t bfr_crystal_lobes(const bfr_material *material, const bfr_geometry *geometry,
                          double wavelength_nm, const double *wi, int32_t transport,
                          bfr_path_lobe out[BFR_CRYSTAL_LOBES], char *message,
                          size_t message_len);

/* Plate seen from wi (either side): out[0] reflection, out[1] transmission.
 * fwhm_nm = 0: exact at wavelength_nm; > 0: closed-form integral over a Gaussian band of that
 * full width at half maximum. flags: BFR_WANT_* | BFR_INTENSITY_ONLY. */
int32_t bfr_plate_lobes(const bfr_material *material, const bfr_geometry *geometry,
                        double wavelength_nm, double fwhm_nm, const double *wi,
                        int32_t transport, int32_t flags, bfr_path_lobe out[2], char *message,
                        size_t message_len);

/* Most wavelengths of one bfr_plate_lobes_n query. */
#define BFR_MAX_BANDS 4

/* bfr_plate_lobes at count (1..BFR_MAX_BANDS) wavelengths at once, the same fwhm_nm for all:
 * out[2 i], out[2 i + 1] for wavelengths_nm[i]. The plate's wavelength-independent work is done
 * once (the wavelengths a spectral renderer traces along one path). */
int32_t bfr_plate_lobes_n(const bfr_material *material, const bfr_geometry *geometry,
                          const double *wavelengths_nm, size_t count, double fwhm_nm,
                          const double *wi, int32_t transport, int32_t flags,
                          bfr_path_lobe *out, char *message, size_t message_len);

/* Plate integrated in closed form over the linear sRGB (D65) channel weights (each normalised
 * so that a spectrally flat response of 1 gives 1): out[c][0..2] for channels c = R, G, B. */
int32_t bfr_plate_lobes_rgb(const bfr_material *material, const bfr_geometry *geometry,
                            const double *wi, int32_t transport, int32_t flags,
                            bfr_path_lobe out[3][2], char *message, size_t message_len);

/* Library version, static NUL-terminated string. */
const char *bfr_version(void);

#ifdef __cplusplus
}
#endif

#endif /* BIREFRINGENT_H */
