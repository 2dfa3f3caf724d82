/* A small, strict, bounded JSON reader: Python's json.loads in C (see json_text.h).
 *
 * The scanner follows CPython's _json.c (scan_once, _parse_object, _parse_array,
 * scanstring, _match_number) step by step, so it accepts, refuses and positions its
 * messages as json.loads does. */
#include "fp_contract.h"
#include "json_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_number.h"
#include "json_string.h"

static const JsonValue EMPTY_VALUE;

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

static size_t skip_space(const JsonScanner *scanner, size_t at)
{
    while (at < scanner->length && is_space(scanner->text[at])) {
        at++;
    }
    return at;
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static int scan_value(JsonScanner *scanner, size_t at, int depth, JsonValue *out, size_t *next);

/* Add `value` (and `key` for an object) to `container`; a repeated key keeps its place and
 * takes the new value, as a dict does. 1: out of memory, 2: too many members. */
static int add_member(JsonValue *container, JsonValue *key, JsonValue *value, size_t *capacity)
{
    size_t i;
    if (key != NULL) {
        if (container->count >= JSON_TEXT_MAX_MEMBERS) {
            return 2;
        }
        for (i = 0; i < container->count; i++) {
            if (container->keys[i].length == key->length
                && memcmp(container->keys[i].text, key->text, key->length) == 0) {
                json_value_free(&container->items[i]);
                container->items[i] = *value;
                json_value_free(key);
                return 0;
            }
        }
    }
    if (container->count == *capacity) {
        size_t grown = *capacity == 0 ? 8 : *capacity * 2;
        JsonValue *items = (JsonValue *)realloc(container->items, grown * sizeof *items);
        if (items == NULL) {
            return 1;
        }
        container->items = items;
        if (key != NULL) {
            JsonValue *keys = (JsonValue *)realloc(container->keys, grown * sizeof *keys);
            if (keys == NULL) {
                return 1;
            }
            container->keys = keys;
        }
        *capacity = grown;
    }
    if (key != NULL) {
        container->keys[container->count] = *key;
    }
    container->items[container->count++] = *value;
    return 0;
}

/* _parse_object / _parse_array: the container whose bracket is at at - 1. */
static int scan_container(JsonScanner *scanner, size_t at, int depth, int object, JsonValue *out,
                          size_t *next)
{
    size_t capacity = 0, len = scanner->length;
    const char *text = scanner->text;
    char close = object ? '}' : ']';
    *out = EMPTY_VALUE;
    out->kind = object ? JSON_OBJECT : JSON_ARRAY;
    at = skip_space(scanner, at);
    if (at >= len || text[at] != close) {
        for (;;) {
            JsonValue key = EMPTY_VALUE, value;
            int added;
            if (object) {
                if (at >= len || text[at] != '"') {
                    return json_fail(scanner, "Expecting property name enclosed in double quotes",
                                at);
                }
                if (json_scan_string(scanner, at + 1, &key, &at)) {
                    return 1;
                }
                at = skip_space(scanner, at);
                if (at >= len || text[at] != ':') {
                    json_value_free(&key);
                    return json_fail(scanner, "Expecting ':' delimiter", at);
                }
                at = skip_space(scanner, at + 1);
            }
            if (scan_value(scanner, at, depth, &value, &at)) {
                json_value_free(&key);
                return 1;
            }
            added = add_member(out, object ? &key : NULL, &value, &capacity);
            if (added != 0) {
                json_value_free(&key);
                json_value_free(&value);
                if (added == 2) {
                    snprintf(scanner->error, scanner->error_size, "an object has more than %d "
                             "members", JSON_TEXT_MAX_MEMBERS);
                    return 1;
                }
                return json_fail(scanner, "out of memory", at);
            }
            at = skip_space(scanner, at);
            if (at < len && text[at] == close) {
                break;
            }
            if (at >= len || text[at] != ',') {
                return json_fail(scanner, "Expecting ',' delimiter", at);
            }
            at = skip_space(scanner, at + 1);
        }
    }
    *next = at + 1;
    return 0;
}

/* Does the literal `word` start at `at`? */
static int literal(const JsonScanner *scanner, size_t at, const char *word)
{
    size_t n = strlen(word);
    return at + n <= scanner->length && strncmp(scanner->text + at, word, n) == 0;
}

/* _match_number: a number starting at `at` (Expecting value when there is none). */
static int scan_number(JsonScanner *scanner, size_t at, JsonValue *out, size_t *next)
{
    const char *text = scanner->text;
    size_t len = scanner->length, start = at, digits;
    int is_float = 0;
    *out = EMPTY_VALUE;
    out->kind = JSON_NUMBER;
    if (text[at] == '-' && ++at >= len) {
        return json_fail(scanner, "Expecting value", start);
    }
    if (text[at] >= '1' && text[at] <= '9') {
        while (++at < len && is_digit(text[at])) {
        }
    } else if (text[at] == '0') {
        at++;
    } else {
        return json_fail(scanner, "Expecting value", start);
    }
    digits = at - start - (text[start] == '-');
    if (at + 1 < len && text[at] == '.' && is_digit(text[at + 1])) {
        is_float = 1;
        for (at += 2; at < len && is_digit(text[at]); at++) {
        }
    }
    if (at + 1 < len && (text[at] == 'e' || text[at] == 'E')) {
        size_t e_start = at++;
        if (at + 1 < len && (text[at] == '-' || text[at] == '+')) {
            at++;
        }
        while (at < len && is_digit(text[at])) {
            at++;
        }
        if (is_digit(text[at - 1])) {
            is_float = 1;
        } else {
            at = e_start;
        }
    }
    if (!is_float && digits > JSON_TEXT_MAX_INT_DIGITS) {
        snprintf(scanner->error, scanner->error_size, "Exceeds the limit (%d digits) for "
                 "integer string conversion: value has %lu digits; use "
                 "sys.set_int_max_str_digits() to increase the limit",
                 JSON_TEXT_MAX_INT_DIGITS, (unsigned long)digits);
        return 1;
    }
    if (json_number_value(text + start, at - start, &out->number)) {
        return json_fail(scanner, "Expecting value", start);
    }
    out->integer = !is_float;
    if (out->integer && out->number == 0.0) {
        out->number = 0.0;        /* int("-0") is 0 */
    }
    out->text = (char *)malloc(at - start + 1);
    if (out->text == NULL) {
        return json_fail(scanner, "out of memory", start);
    }
    memcpy(out->text, text + start, at - start);
    out->text[at - start] = '\0';
    out->length = at - start;
    *next = at;
    return 0;
}

/* scan_once: the value starting at `at`. */
static int scan_value(JsonScanner *scanner, size_t at, int depth, JsonValue *out, size_t *next)
{
    *out = EMPTY_VALUE;
    if (at >= scanner->length) {
        return json_fail(scanner, "Expecting value", at);
    }
    switch (scanner->text[at]) {
    case '"':
        return json_scan_string(scanner, at + 1, out, next);
    case '{':
    case '[':
        if (depth >= JSON_TEXT_MAX_DEPTH) {
            snprintf(scanner->error, scanner->error_size, "maximum recursion depth exceeded while "
                     "decoding a JSON %s from a unicode string",
                     scanner->text[at] == '{' ? "object" : "array");
            return 1;
        }
        if (scan_container(scanner, at + 1, depth + 1, scanner->text[at] == '{', out, next)) {
            json_value_free(out);
            return 1;
        }
        return 0;
    case 'n':
    case 't':
    case 'f': {
        static const char *const words[3] = {"null", "true", "false"};
        static const JsonKind kinds[3] = {JSON_NULL, JSON_TRUE, JSON_FALSE};
        int which = scanner->text[at] == 'n' ? 0 : scanner->text[at] == 't' ? 1 : 2;
        if (literal(scanner, at, words[which])) {
            out->kind = kinds[which];
            *next = at + strlen(words[which]);
            return 0;
        }
        break;
    }
    case 'N':
    case 'I':
    case '-': {
        const char *word = scanner->text[at] == 'N' ? "NaN"
                           : scanner->text[at] == 'I' ? "Infinity" : "-Infinity";
        if (literal(scanner, at, word)) {
            out->kind = JSON_NUMBER;
            out->number = word[0] == 'N' ? NAN : word[0] == 'I' ? HUGE_VAL : -HUGE_VAL;
            out->length = strlen(word);
            out->text = (char *)malloc(out->length + 1);
            if (out->text == NULL) {
                return json_fail(scanner, "out of memory", at);
            }
            memcpy(out->text, word, out->length + 1);
            *next = at + out->length;
            return 0;
        }
        break;
    }
    default:
        break;
    }
    return scan_number(scanner, at, out, next);
}

int json_text_parse(const char *text, JsonValue *out, char *error, size_t error_size)
{
    JsonScanner scanner;
    size_t at, valid;
    *out = EMPTY_VALUE;
    scanner.text = text;
    for (scanner.length = 0; scanner.length <= JSON_TEXT_MAX_BYTES && text[scanner.length] != '\0';
         scanner.length++) {
    }
    scanner.error = error;
    scanner.error_size = error_size;
    if (scanner.length > JSON_TEXT_MAX_BYTES) {
        snprintf(error, error_size, "the text is longer than %d bytes", JSON_TEXT_MAX_BYTES);
        return 1;
    }
    valid = json_valid_utf8((const unsigned char *)text, scanner.length);
    if (valid != scanner.length) {
        snprintf(error, error_size, "invalid UTF-8 at byte %lu", (unsigned long)valid);
        return 1;
    }
    if (scanner.length >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) {
        return json_fail(&scanner, "Unexpected UTF-8 BOM (decode using utf-8-sig)", 0);
    }
    if (scan_value(&scanner, skip_space(&scanner, 0), 0, out, &at)) {
        json_value_free(out);
        return 1;
    }
    at = skip_space(&scanner, at);
    if (at != scanner.length) {
        json_value_free(out);
        return json_fail(&scanner, "Extra data", at);
    }
    return 0;
}

void json_value_free(JsonValue *value)
{
    size_t i;
    for (i = 0; i < value->count; i++) {
        json_value_free(&value->items[i]);
        if (value->keys != NULL) {
            json_value_free(&value->keys[i]);
        }
    }
    free(value->items);
    free(value->keys);
    free(value->text);
    *value = EMPTY_VALUE;
}
