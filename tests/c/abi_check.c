/* Drives the C ABI through the public header; prints one line per check for tests/c_abi.rs. */
#include "birefringent.h"
#include <math.h>
#include <stdio.h>

static void print_lobe(const char *tag, const bfr_path_lobe *l) {
    printf("%s %d %d %.17g %.17g %.17g %.17g %.17g %.17g\n", tag, l->exists, l->component, l->wo[0],
           l->wo[1], l->wo[2], l->weight, l->mueller[5], l->eta);
}

int main(void) {
    printf("sizes %zu %zu %zu %zu\n", sizeof(bfr_complex), sizeof(bfr_material_desc),
           sizeof(bfr_geometry), sizeof(bfr_path_lobe));
    printf("version %s\n", bfr_version());
    char msg[256];

    bfr_material_desc desc = {"calcite", {0, 0}, {0, 0}, 0.0, 0.0};
    bfr_material *calcite = bfr_material_new(&desc, msg, sizeof msg);
    bfr_complex eo, ee;
    int32_t rc = bfr_material_indices(calcite, 589.3, &eo, &ee);
    printf("indices %d %.17g %.17g\n", rc, eo.re, ee.re);

    bfr_geometry g = {1.0, 1.0, {0.7021, 0.0, 0.7120}, 2500.0, 0.0};
    double wi[3] = {0.3, 0.2, sqrt(1.0 - 0.13)};
    bfr_path_lobe lobes[BFR_CRYSTAL_LOBES];
    for (int t = 0; t < 2; ++t) {
        rc = bfr_crystal_lobes(calcite, &g, 589.3, wi, t, lobes, msg, sizeof msg);
        printf("crystal %d %d\n", t, rc);
        for (int i = 0; i < BFR_CRYSTAL_LOBES; ++i) print_lobe("lobe", &lobes[i]);
    }

    bfr_path_lobe plate[2];
    rc = bfr_plate_lobes(calcite, &g, 550.0, 0.0, wi, BFR_RADIANCE,
                         BFR_WANT_REFLECTION | BFR_WANT_TRANSMISSION, plate, msg, sizeof msg);
    printf("plate %d\n", rc);
    print_lobe("lobe", &plate[0]);
    print_lobe("lobe", &plate[1]);
    bfr_path_lobe rgb[3][2];
    rc = bfr_plate_lobes_rgb(calcite, &g, wi, BFR_IMPORTANCE,
                             BFR_WANT_TRANSMISSION | BFR_INTENSITY_ONLY, rgb, msg, sizeof msg);
    printf("rgb %d %.17g %.17g %.17g %d\n", rc, rgb[0][1].weight, rgb[1][1].weight,
           rgb[2][1].weight, rgb[0][0].exists);

    const double waves[3] = {450.0, 550.0, 650.0};
    bfr_path_lobe multi[2 * BFR_MAX_BANDS];
    rc = bfr_plate_lobes_n(calcite, &g, waves, 3, 4.0, wi, BFR_RADIANCE,
                           BFR_WANT_REFLECTION | BFR_WANT_TRANSMISSION, multi, msg, sizeof msg);
    printf("bands %d\n", rc);
    for (int i = 0; i < 6; ++i) print_lobe("lobe", &multi[i]);
    rc = bfr_plate_lobes_n(calcite, &g, waves, BFR_MAX_BANDS + 1, 4.0, wi, BFR_RADIANCE, 3,
                           multi, msg, sizeof msg);
    printf("too many %d %s\n", rc, msg);

    bfr_material_desc bad_desc = {"unobtainium", {0, 0}, {0, 0}, 0.0, 0.0};
    bfr_material *none = bfr_material_new(&bad_desc, msg, sizeof msg);
    printf("bad material %d %s\n", none == NULL, msg);
    bfr_geometry bad = g;
    bad.optic_axis[0] = bad.optic_axis[1] = bad.optic_axis[2] = 0.0;
    rc = bfr_crystal_lobes(calcite, &bad, 589.3, wi, 0, lobes, msg, sizeof msg);
    printf("bad axis %d %s\n", rc, msg);
    rc = bfr_crystal_lobes(calcite, &g, 589.3, wi, 7, lobes, msg, 10);
    printf("truncated %d [%s]\n", rc, msg);
    rc = bfr_plate_lobes(calcite, NULL, 550.0, 0.0, wi, 0, 3, plate, msg, sizeof msg);
    printf("null %d %s\n", rc, msg);
    bfr_material_free(calcite);
    bfr_material_free(NULL);
    return 0;
}
