/* Integer codes of named settings (sma_choices.h; slave_support/choices.py). */
#include "fp_contract.h"
#include <string.h>

#include "sma_choices.h"

static const char *const HYSTERESIS_MODE_NAMES[] = {"continuous", "switch"};
static const char *const INVERSE_NAMES[] = {"major", "minor-loop"};
static const char *const SHAPING_NAMES[] = {"none", "reachable"};
static const char *const MODULATION_NAMES[] = {"pwm", "linear"};

int choice_name(const char *parameter, int code, const char **name, SmaMessage *message)
{
    const char *const *names = strcmp(parameter, "inverse") == 0      ? INVERSE_NAMES
                               : strcmp(parameter, "shaping") == 0    ? SHAPING_NAMES
                               : strcmp(parameter, "modulation") == 0 ? MODULATION_NAMES
                                                                      : HYSTERESIS_MODE_NAMES;
    if (code == 1 || code == 2) {
        *name = names[code - 1];
        return 0;
    }
    return sma_message_set(message, "%s must be 1 (%s) or 2 (%s), got %d", parameter, names[0],
                           names[1], code);
}
