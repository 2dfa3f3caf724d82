/* Validity warnings; runtime/validity.py (see validity.h). */
#include "fp_contract.h"
#include "validity.h"

#include <stdio.h>

int validity_warning(const WireParameters *params, double temperature, double temperature_before,
                     double load, double load_before, char *text, size_t size)
{
    char hot[128] = "", heavy[192] = "";
    int is_hot = temperature > params->T_max && params->T_max >= temperature_before;
    int is_heavy = load > params->load_max && params->load_max >= load_before;
    if (is_hot) {
        snprintf(hot, sizeof hot, "T = %.6g degC rose above validity.T_max = %g degC",
                 temperature, params->T_max);
    }
    if (is_heavy) {
        snprintf(heavy, sizeof heavy, "load = %.6g kg rose above the validity limit %.4g kg "
                 "(validity.stress_max = %g MPa on a %g mm wire)", load, params->load_max,
                 params->stress_max, params->diameter * 1e3);
    }
    if (!is_hot && !is_heavy) {
        if (size > 0) {
            text[0] = '\0';
        }
        return 0;
    }
    snprintf(text, size, "%s%s%s: outside the range the model's parameters describe", hot,
             is_hot && is_heavy ? "; " : "", heavy);
    return 1;
}
