/* The wire model's validity range: warnings when the temperature or the load leaves it,
 * or leaves the range the wire's data covered; runtime/validity.py. */
#ifndef SMA_VALIDITY_H
#define SMA_VALIDITY_H

#include <stddef.h>

#include "parameters.h"

/* validity.DATA_RANGE_NOTE: how every data-range warning ends */
#define SMA_DATA_RANGE_NOTE "outside the range of the data the wire's parameters were fitted " \
    "to (warned once per instance)"

/* The warning for a step that took T [degC] / load [kg] above validity.T_max / load_max
 * from at or below them, written to text[size]; "" (Python's None) when there is none.
 * Returns 1 when a warning was written, else 0. */
int validity_warning(const WireParameters *params, double temperature, double temperature_before,
                     double load, double load_before, char *text, size_t size);

/* The warning when the temperature `name` [degC] or the load [kg] lies outside the data
 * range of params (T_data_min ... stress_data_max; a bound not given, NaN, does not apply),
 * appended to text[size] after "; " when text is not empty; text unchanged when there is
 * none. Returns 1 when a warning was written, else 0. */
int data_range_warning(const WireParameters *params, double temperature, double load,
                       const char *name, char *text, size_t size);

#endif
