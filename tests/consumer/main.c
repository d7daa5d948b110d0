/* A program as a user writes it: only <dwivedi.h> and the installed library. */
#include <dwivedi.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

int main(void)
{
    char expected[32];
    snprintf(expected, sizeof expected, "%d.%d.%d", DWV_VERSION_MAJOR, DWV_VERSION_MINOR, DWV_VERSION_PATCH);
    if (dwv_version() != DWV_VERSION || strcmp(dwv_version_string(), expected) != 0) {
        fprintf(stderr, "version mismatch: header %d, library %u (%s)\n", DWV_VERSION, dwv_version(),
                dwv_version_string());
        return 1;
    }
    dwv_diffusion_length_t d = DWV_DIFFUSION_LENGTH_INIT;
    if (dwv_diffusion_length(0.5, DWV_V0_EXACT, &d) != DWV_SUCCESS) {
        fprintf(stderr, "dwv_diffusion_length failed: %s\n", dwv_last_error_message());
        return 1;
    }
    /* kappa0(0.5) = 0.957504024..., a reference value from the mpmath table in tests/data. */
    if (fabs(d.kappa - 0.9575040240772687) > 1e-14) {
        fprintf(stderr, "kappa0(0.5) = %.17g\n", d.kappa);
        return 1;
    }
    if (dwv_diffusion_length(2.0, DWV_V0_EXACT, &d) != DWV_ERROR_OUT_OF_RANGE) {
        fprintf(stderr, "albedo 2 was accepted\n");
        return 1;
    }
    printf("consumer: kappa0(0.5) = %.17g; error message for albedo 2: %s\n", 0.9575040240772687,
           dwv_last_error_message());
    return 0;
}
