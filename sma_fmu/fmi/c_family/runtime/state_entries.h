/* Reading a stepper's saved state as carefully as an input; runtime/state_entries.py.
 *
 * In C a saved state is an array of doubles whose layout each stepper documents in its
 * header (the FMI layer wraps it with the model name, format version and count). Every
 * entry is checked for range before a stepper changes anything; a refusal (Python's
 * StateError) fills `message` naming the entry and the value and returns 1, so a state is
 * either taken whole or refused whole.
 *
 * Python's None (a memory not yet filled) is stored as NaN: SMA_STATE_NONE. Python's
 * [low, high] defaults of -inf / +inf are -HUGE_VAL / HUGE_VAL here. */
#ifndef SMA_STATE_ENTRIES_H
#define SMA_STATE_ENTRIES_H

#include <math.h>
#include <stddef.h>

#include "sma_message.h"

#define SMA_STATE_NONE NAN            /* the stored form of Python's None */
#define sma_state_is_none(value) isnan(value)

/* Refuse a format text that is not `expected` (as check_format): "the <what> has format ...". */
int check_format(const char *found, const char *expected, const char *what,
                 SmaMessage *message);
/* Refuse a state of `count` doubles unless it holds exactly `required` ("the <what> holds
 * ... numbers, not ..."): C's form of read_entries (missing/unknown entries). */
int read_entries(size_t count, size_t required, const char *what, SmaMessage *message);
/* `value` must be finite and in [low, high] (unit "" = none), else
 * "state entry <key> = <value> must be finite and in [low, high] unit". */
int read_number(double value, const char *key, double low, double high, const char *unit,
                SmaMessage *message);
/* read_number, or *present = 0 where `value` is the stored None (*present = 1 otherwise). */
int read_optional_number(double value, const char *key, double low, double high,
                         const char *unit, int *present, SmaMessage *message);
/* A temperature [degC] above absolute zero and at most `high`; with `optional` nonzero the
 * stored None is accepted (*present = 0). `present` may be NULL when not optional. */
int read_temperature(double value, const char *key, double high, int optional, int *present,
                     SmaMessage *message);
/* `value` must be exactly 1 (heating) or -1 (cooling) -> *direction. NULL key = "direction". */
int read_direction(double value, const char *key, int *direction, SmaMessage *message);

#endif
