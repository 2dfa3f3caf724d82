/* Reading a stepper's saved state; runtime/state_entries.py (see state_entries.h). */
#include "fp_contract.h"
#include "state_entries.h"

#include <string.h>

#include "constants.h"

int check_format(const char *found, const char *expected, const char *what,
                 SmaMessage *message)
{
    if (found != NULL && strcmp(found, expected) == 0) {
        return 0;
    }
    return sma_message_set(
        message, "the %s has format %s%.100s%s, not '%s': it was saved by an earlier sma-fmu "
        "build (minor-loop memory of one reversal) and cannot be restored by this one",
        what, found != NULL ? "'" : "", found != NULL ? found : "None", found != NULL ? "'" : "",
        expected);
}

int read_entries(size_t count, size_t required, const char *what, SmaMessage *message)
{
    if (count != required) {
        return sma_message_set(message, "the %s holds %lu numbers, not %lu", what,
                               (unsigned long)count, (unsigned long)required);
    }
    return 0;
}

int read_number(double value, const char *key, double low, double high, const char *unit,
                SmaMessage *message)
{
    if (!(isfinite(value) && low <= value && value <= high)) {
        return sma_message_set(message, "state entry %s = %.17g must be finite and in [%g, %g]%s%s",
                               key, value, low, high, unit[0] != '\0' ? " " : "", unit);
    }
    return 0;
}

int read_optional_number(double value, const char *key, double low, double high,
                         const char *unit, int *present, SmaMessage *message)
{
    if (sma_state_is_none(value)) {
        *present = 0;
        return 0;
    }
    *present = 1;
    return read_number(value, key, low, high, unit, message);
}

int read_temperature(double value, const char *key, double high, int optional, int *present,
                     SmaMessage *message)
{
    if (optional && sma_state_is_none(value)) {
        *present = 0;
        return 0;
    }
    if (present != NULL) {
        *present = 1;
    }
    if (read_number(value, key, -KELVIN_OFFSET, high, "degC", message)) {
        return 1;
    }
    if (value == -KELVIN_OFFSET) {
        return sma_message_set(message, "state entry %s = %.17g degC must be above -273.15 degC",
                               key, value);
    }
    return 0;
}

int read_direction(double value, const char *key, int *direction, SmaMessage *message)
{
    if (key == NULL) {
        key = "direction";
    }
    if (value == 1.0 || value == -1.0) {
        *direction = value > 0.0 ? 1 : -1;
        return 0;
    }
    return sma_message_set(message, "state entry %s must be 1 (heating) or -1 (cooling), got %.17g",
                           key, value);
}
