/* Argument checks that refuse naming the argument and the offending value; runtime/checks.py.
 *
 * Each returns 0 when the value passes, else fills `message` (Python's ValueError text,
 * doubles printed with %.17g) and returns 1. In C every argument is already a double, so
 * Python's "must be a number" case cannot arise and the fast_* variants equal the require_*
 * ones (kept under Python's names so the ports read side by side). */
#ifndef SMA_CHECKS_H
#define SMA_CHECKS_H

#include <math.h>

#include "sma_message.h"

/* HYSTERESIS_MODES = ("switch", "continuous"): a mode is its index in that tuple. */
typedef enum {
    HYSTERESIS_SWITCH = 0,
    HYSTERESIS_CONTINUOUS = 1
} HysteresisMode;
#define HYSTERESIS_MODE_COUNT 2
extern const char *const HYSTERESIS_MODES[HYSTERESIS_MODE_COUNT];

int require_finite(const char *name, double value, SmaMessage *message);
int require_nonnegative(const char *name, double value, SmaMessage *message);
int require_positive(const char *name, double value, SmaMessage *message);
/* The same checks with the passing case inline (a step checks its inputs every time). */
SMA_INLINE int fast_finite(const char *name, double value, SmaMessage *message)
{
    return -HUGE_VAL < value && value < HUGE_VAL ? 0 : require_finite(name, value, message);
}
SMA_INLINE int fast_nonnegative(const char *name, double value, SmaMessage *message)
{
    return 0.0 <= value && value < HUGE_VAL ? 0 : require_nonnegative(name, value, message);
}
SMA_INLINE int fast_positive(const char *name, double value, SmaMessage *message)
{
    return 0.0 < value && value < HUGE_VAL ? 0 : require_positive(name, value, message);
}

/* direction +1 (HEATING) or -1 (COOLING) -> *sign; else refused naming `name`
 * (NULL name = "direction"). */
int direction_sign(int direction, const char *name, int *sign, SmaMessage *message);
/* "heating"/"cooling" (surrounding blanks and case ignored) -> *sign, else refused. */
int direction_sign_of_text(const char *direction, const char *name, int *sign,
                           SmaMessage *message);
/* +1 -> "heating", anything else -> "cooling" (the caller passes a valid sign). */
const char *direction_name(int sign);

/* `mode` ("switch" or "continuous", exactly) -> *out; else refused naming `name`
 * (NULL name = "mode"; a NULL mode reads as Python's None). */
int require_mode(const char *mode, const char *name, HysteresisMode *out, SmaMessage *message);

#endif
