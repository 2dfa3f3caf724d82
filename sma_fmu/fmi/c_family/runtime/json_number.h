/* Decimal text -> double exactly as Python does it, for json_text.c.
 *
 * json_number_value gives the double nearest a JSON number's decimal value, ties to even
 * (Python's float(text), and float(int) for integers), with exact integer arithmetic:
 * never the C library's strtod, which reads the locale's decimal point (a host may have
 * set a comma) and, in some Windows C libraries, is not correctly rounded. */
#ifndef SMA_JSON_NUMBER_H
#define SMA_JSON_NUMBER_H

#include <stddef.h>

/* text[0..length) must match -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][-+]?[0-9]+)?, else 1.
 * Overflow gives +-HUGE_VAL (as float('1e400')). */
int json_number_value(const char *text, size_t length, double *out);

#endif
