/* Validity warnings; runtime/validity.py (see validity.h). */
#include "fp_contract.h"
#include "validity.h"

#include <stdio.h>
#include <string.h>

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

/* Where the next clause of text[size] starts: after "; " when it already holds one. */
static size_t next_clause(char *text, size_t size)
{
    size_t used = strlen(text);
    if (used > 0 && used + 3 <= size) {
        memcpy(text + used, "; ", 3);
        used += 2;
    }
    return used;
}

int data_range_warning(const WireParameters *params, double temperature, double load,
                       const char *name, char *text, size_t size)
{
    char found[512] = "";
    double mm = params->diameter * 1e3;
    size_t used;
    if (temperature < params->T_data_min) {
        used = next_clause(found, sizeof found);
        snprintf(found + used, sizeof found - used, "%s = %.6g degC is below "
                 "validity.T_data_min = %g degC", name, temperature, params->T_data_min);
    }
    if (temperature > params->T_data_max) {
        used = next_clause(found, sizeof found);
        snprintf(found + used, sizeof found - used, "%s = %.6g degC is above "
                 "validity.T_data_max = %g degC", name, temperature, params->T_data_max);
    }
    if (load < params->load_data_min) {
        used = next_clause(found, sizeof found);
        snprintf(found + used, sizeof found - used, "load = %.6g kg is below %.4g kg "
                 "(validity.stress_data_min = %g MPa on a %g mm wire)", load,
                 params->load_data_min, params->stress_data_min, mm);
    }
    if (load > params->load_data_max) {
        used = next_clause(found, sizeof found);
        snprintf(found + used, sizeof found - used, "load = %.6g kg is above %.4g kg "
                 "(validity.stress_data_max = %g MPa on a %g mm wire)", load,
                 params->load_data_max, params->stress_data_max, mm);
    }
    if (found[0] == '\0' || size == 0) {
        return 0;
    }
    used = next_clause(text, size);
    snprintf(text + used, size - used, "%s: %s", found, SMA_DATA_RANGE_NOTE);
    return 1;
}
