/* Internals of json_text.c shared with json_string.c (not an API for other modules). */
#ifndef SMA_JSON_STRING_H
#define SMA_JSON_STRING_H

#include <stddef.h>

#include "json_text.h"

/* The text being read and where a refusal's message goes. */
typedef struct JsonScanner {
    const char *text;
    size_t length;
    char *error;
    size_t error_size;
} JsonScanner;

/* Python's JSONDecodeError text "<what>: line L column C (char N)" into the scanner's
 * error (positions in characters; `at` is a byte offset); returns 1. */
int json_fail(JsonScanner *scanner, const char *what, size_t at);
/* scanstring: the string whose opening quote is at begin - 1 into *out (JSON_STRING);
 * *next after its closing quote. */
int json_scan_string(JsonScanner *scanner, size_t begin, JsonValue *out, size_t *next);
/* Length of the valid UTF-8 prefix of text[0..length). */
size_t json_valid_utf8(const unsigned char *text, size_t length);

#endif
