/* C ABI of the mitsuba-birefringent Rust core (static library libbirefringent.a).
 *
 * Kept by hand next to src/ffi.rs; tests/c_abi.rs compiles and runs a C program against this
 * header and checks every struct's size and the results against the Rust API.
 *
 * Conventions: local shading frame (z = surface normal towards the exterior, the crystal
 * fills z < 0). Complex indices are n + i kappa with kappa >= 0. Mueller matrices are
 * row-major 4x4 in Mitsuba's convention; a Stokes frame is given by its x axis, with
 * y = (propagation direction) x (x axis). No function unwinds or aborts: errors are returned
 * as codes with a message naming the parameter.
 */
#ifndef BIREFRINGENT_H
#define BIREFRINGENT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define BFR_OK 0       /* success */
#define BFR_INVALID 1  /* invalid input; message names the parameter */
#define BFR_INTERNAL 2 /* a bug (caught panic or non-finite result) */

typedef struct bfr_complex {
    double re, im;
} bfr_complex;

/* A crystal surface under an isotropic exterior, at one wavelength. */
typedef struct bfr_surface {
    bfr_complex ext_ior;   /* exterior index */
    bfr_complex eta_o;     /* ordinary index n_o + i kappa_o */
    bfr_complex eta_e;     /* extraordinary index n_e + i kappa_e */
    double optic_axis[3];  /* local frame, any non-zero length */
} bfr_surface;

/* One outgoing wave. */
typedef struct bfr_lobe {
    int32_t exists;        /* 1 if the wave carries power away from the surface */
    int32_t kind;          /* 0: exterior (or isotropic crystal) s/p wave, 2: o-wave, 3: e-wave */
    double direction[3];   /* unit ray (Poynting) direction, away from the surface */
    double stokes_x[3];    /* x axis of its Stokes frame */
    double mueller[16];    /* incident Stokes -> this wave's Stokes, power fractions */
} bfr_lobe;

/* All lobes of a surface event. */
typedef struct bfr_event {
    double incident_stokes_x[3]; /* x axis of the incident wave's Stokes frame */
    bfr_lobe reflected[2];       /* outside incidence: [exterior, -]; inside: [o, e] */
    bfr_lobe transmitted[2];     /* outside incidence: [o, e]; inside: [exterior, -] */
} bfr_event;

/* Light arriving from the unit local direction towards_light[3].
 * incident: 0 = from the exterior (towards_light z > 0); 1 = an o-wave, 2 = an e-wave inside
 * the crystal (z < 0; towards_light is minus its ray direction).
 * Returns BFR_OK and fills *out, or an error code and a NUL-terminated message (truncated to
 * message_len bytes; message may be NULL). */
int32_t bfr_surface_scatter(const bfr_surface *surface, const double *towards_light,
                            int32_t incident, bfr_event *out, char *message,
                            size_t message_len);

/* Library version, static NUL-terminated string. */
const char *bfr_version(void);

#ifdef __cplusplus
}
#endif

#endif /* BIREFRINGENT_H */
