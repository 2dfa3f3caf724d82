/* Argument checks; runtime/checks.py (see checks.h). */
#include "fp_contract.h"
#include "checks.h"

#include <ctype.h>
#include <math.h>
#include <string.h>

#include "constants.h"

const char *const HYSTERESIS_MODES[HYSTERESIS_MODE_COUNT] = {"switch", "continuous"};

int require_finite(const char *name, double value, SmaMessage *message)
{
    if (!isfinite(value)) {
        return sma_message_set(message, "%s must be finite, got %.17g", name, value);
    }
    return 0;
}

int require_nonnegative(const char *name, double value, SmaMessage *message)
{
    if (require_finite(name, value, message)) {
        return 1;
    }
    if (value < 0.0) {
        return sma_message_set(message, "%s must be >= 0, got %.17g", name, value);
    }
    return 0;
}

int require_positive(const char *name, double value, SmaMessage *message)
{
    if (require_finite(name, value, message)) {
        return 1;
    }
    if (value <= 0.0) {
        return sma_message_set(message, "%s must be > 0, got %.17g", name, value);
    }
    return 0;
}

int direction_sign(int direction, const char *name, int *sign, SmaMessage *message)
{
    if (direction == HEATING || direction == COOLING) {
        *sign = direction;
        return 0;
    }
    return sma_message_set(message, "%s must be 'heating' (+1) or 'cooling' (-1), got %d",
                           name != NULL ? name : "direction", direction);
}

/* Is `text`, blanks stripped and lower-cased, equal to `word`? */
static int same_word(const char *text, const char *word)
{
    size_t start = 0, end = strlen(text), length = strlen(word), i;
    while (start < end && isspace((unsigned char)text[start])) {
        start++;
    }
    while (end > start && isspace((unsigned char)text[end - 1])) {
        end--;
    }
    if (end - start != length) {
        return 0;
    }
    for (i = 0; i < length; i++) {
        if (tolower((unsigned char)text[start + i]) != word[i]) {
            return 0;
        }
    }
    return 1;
}

int direction_sign_of_text(const char *direction, const char *name, int *sign,
                           SmaMessage *message)
{
    if (direction != NULL && same_word(direction, "heating")) {
        *sign = HEATING;
        return 0;
    }
    if (direction != NULL && same_word(direction, "cooling")) {
        *sign = COOLING;
        return 0;
    }
    if (direction == NULL) {
        return sma_message_set(message, "%s must be 'heating' (+1) or 'cooling' (-1), got None",
                               name != NULL ? name : "direction");
    }
    return sma_message_set(message, "%s must be 'heating' (+1) or 'cooling' (-1), got '%.200s'",
                           name != NULL ? name : "direction", direction);
}

const char *direction_name(int sign)
{
    return sign == HEATING ? "heating" : "cooling";
}

int require_mode(const char *mode, const char *name, HysteresisMode *out, SmaMessage *message)
{
    int index;
    if (name == NULL) {
        name = "mode";
    }
    if (mode == NULL) {
        return sma_message_set(message, "%s must be one of switch, continuous, got None", name);
    }
    for (index = 0; index < HYSTERESIS_MODE_COUNT; index++) {
        if (strcmp(mode, HYSTERESIS_MODES[index]) == 0) {
            *out = (HysteresisMode)index;
            return 0;
        }
    }
    return sma_message_set(message, "%s must be one of switch, continuous, got '%.200s'",
                           name, mode);
}
