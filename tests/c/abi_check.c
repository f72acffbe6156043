/* Drives the C ABI through the public header; prints one line per check for tests/c_abi.rs. */
#include "birefringent.h"
#include <math.h>
#include <stdio.h>

int main(void) {
    printf("sizes %zu %zu %zu %zu\n", sizeof(bfr_complex), sizeof(bfr_surface), sizeof(bfr_lobe),
           sizeof(bfr_event));
    printf("version %s\n", bfr_version());

    bfr_surface s = {{1.0, 0.0}, {1.6584, 0.0}, {1.4864, 0.0}, {0.7021, 0.0, 0.7120}};
    double w[3] = {0.3, 0.2, sqrt(1.0 - 0.13)};
    bfr_event e;
    char msg[256];
    int32_t rc = bfr_surface_scatter(&s, w, 0, &e, msg, sizeof msg);
    printf("rc %d\n", rc);
    const bfr_lobe *lobes[4] = {&e.reflected[0], &e.reflected[1], &e.transmitted[0], &e.transmitted[1]};
    for (int i = 0; i < 4; ++i) {
        const bfr_lobe *l = lobes[i];
        printf("lobe %d %d %.17g %.17g %.17g %.17g %.17g\n", l->exists, l->kind, l->direction[0],
               l->direction[1], l->direction[2], l->mueller[0], l->mueller[5]);
    }

    bfr_surface bad = s;
    bad.optic_axis[0] = bad.optic_axis[1] = bad.optic_axis[2] = 0.0;
    rc = bfr_surface_scatter(&bad, w, 0, &e, msg, sizeof msg);
    printf("bad %d %s\n", rc, msg);
    rc = bfr_surface_scatter(&s, w, 7, &e, msg, 8);
    printf("truncated %d [%s]\n", rc, msg);
    rc = bfr_surface_scatter(NULL, w, 0, &e, msg, sizeof msg);
    printf("null %d %s\n", rc, msg);
    return 0;
}
