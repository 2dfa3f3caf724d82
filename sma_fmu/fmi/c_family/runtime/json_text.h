/* A small, strict, bounded JSON reader for the String parameters of scenario_signals.c:
 * Python's json.loads, as scenario_signals.py calls it, in C.
 *
 * It accepts what json.loads accepts and refuses what it refuses, with the decoder's
 * message ("Expecting value: line 1 column 1 (char 0)", positions in characters):
 * objects (a repeated key keeps its first place and its last value, like a dict), arrays,
 * strings (strict: no raw control characters; \uXXXX escapes and surrogate pairs), numbers,
 * true/false/null and Python's NaN, Infinity, -Infinity (json.loads takes them; the signal
 * checks then refuse them naming the key, as in Python). Beyond Python it refuses, with a
 * message, text longer than JSON_TEXT_MAX_BYTES, nesting deeper than JSON_TEXT_MAX_DEPTH
 * (Python's RecursionError message), objects of more than JSON_TEXT_MAX_MEMBERS members
 * and invalid UTF-8.
 *
 * Numbers are converted exactly as Python's float() and float(int) do (json_number.h). */
#ifndef SMA_JSON_TEXT_H
#define SMA_JSON_TEXT_H

#include <stddef.h>

#define JSON_TEXT_MAX_BYTES 8388608   /* choice: 8 MiB, a load table of ~400 000 points */
#define JSON_TEXT_MAX_DEPTH 64        /* choice: a signal table nests 2 deep */
#define JSON_TEXT_MAX_MEMBERS 256     /* choice: a signal table has at most 5 keys; bounds
                                         the repeated-key search */
#define JSON_TEXT_MAX_INT_DIGITS 4300 /* Python's int_max_str_digits default */

typedef enum JsonKind {
    JSON_NULL, JSON_FALSE, JSON_TRUE, JSON_NUMBER, JSON_STRING, JSON_ARRAY, JSON_OBJECT
} JsonKind;

typedef struct JsonValue {
    JsonKind kind;
    int integer;            /* JSON_NUMBER written without fraction or exponent (Python int) */
    double number;          /* JSON_NUMBER: the double nearest its decimal value */
    char *text;             /* JSON_STRING: decoded UTF-8, NUL-terminated; JSON_NUMBER: as
                               written */
    size_t length;          /* bytes in text (a string may hold \u0000) */
    size_t count;           /* JSON_ARRAY items, JSON_OBJECT members */
    struct JsonValue *items;  /* the items, or the members' values */
    struct JsonValue *keys;   /* JSON_OBJECT: the members' names (JSON_STRING), in order */
} JsonValue;

/* Parse NUL-terminated `text` into *out (free it with json_value_free). On a refusal returns
 * 1, leaves *out empty (JSON_NULL) and writes the message into error[error_size]. */
int json_text_parse(const char *text, JsonValue *out, char *error, size_t error_size);
void json_value_free(JsonValue *value);

/* Does JSON_STRING `key` equal the NUL-terminated `name` (all of its bytes)? */
int json_string_is(const JsonValue *key, const char *name);
/* The value of member `name` of JSON_OBJECT `object`, or NULL. */
const JsonValue *json_object_get(const JsonValue *object, const char *name);

/* Python's repr() of a loaded value / of a string, written into out[size] (truncated,
 * always NUL-terminated); for messages. */
void json_value_repr(const JsonValue *value, char *out, size_t size);
void json_text_repr(const char *text, size_t length, char *out, size_t size);
/* Python's repr(float(number)): the shortest digits that read back to it. */
void json_float_repr(double number, char *out, size_t size);

#endif
