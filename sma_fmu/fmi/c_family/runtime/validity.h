/* The wire model's validity range: warnings when the temperature or the load leaves it;
 * runtime/validity.py. */
#ifndef SMA_VALIDITY_H
#define SMA_VALIDITY_H

#include <stddef.h>

#include "parameters.h"

/* The warning for a step that took T [degC] / load [kg] above validity.T_max / load_max
 * from at or below them, written to text[size]; "" (Python's None) when there is none.
 * Returns 1 when a warning was written, else 0. */
int validity_warning(const WireParameters *params, double temperature, double temperature_before,
                     double load, double load_before, char *text, size_t size);

#endif
