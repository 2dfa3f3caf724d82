/* A small, strict, bounded JSON reader: Python's json.loads in C (see json_text.h).
 *
 * The scanner follows CPython's _json.c (scan_once, _parse_object, _parse_array,
 * scanstring, _match_number) step by step, so it accepts, refuses and positions its
 * messages as json.loads does. */
#include "json_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_number.h"

typedef struct Scanner {
    const char *text;
    size_t length;
    char *error;
    size_t error_size;
} Scanner;

static const JsonValue EMPTY_VALUE;

/* Python's JSONDecodeError text: "<what>: line L column C (char N)", N in characters. */
static int fail(Scanner *scanner, const char *what, size_t at)
{
    size_t i, line = 1, column = 1, chars = 0;
    for (i = 0; i < at && i < scanner->length; i++) {
        unsigned char byte = (unsigned char)scanner->text[i];
        if ((byte & 0xC0) == 0x80) {
            continue;             /* a UTF-8 continuation byte: not a new character */
        }
        chars++;
        column++;
        if (byte == '\n') {
            line++;
            column = 1;
        }
    }
    snprintf(scanner->error, scanner->error_size, "%s: line %lu column %lu (char %lu)", what,
             (unsigned long)line, (unsigned long)column, (unsigned long)chars);
    return 1;
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

static size_t skip_space(const Scanner *scanner, size_t at)
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

/* Append bytes to a growing buffer; 1 when memory runs out. */
static int append(char **buffer, size_t *length, size_t *capacity, const char *bytes,
                  size_t count)
{
    if (*length + count + 1 > *capacity) {
        size_t grown = (*capacity == 0 ? 16 : *capacity * 2) + count;
        char *bigger = (char *)realloc(*buffer, grown);
        if (bigger == NULL) {
            return 1;
        }
        *buffer = bigger;
        *capacity = grown;
    }
    memcpy(*buffer + *length, bytes, count);
    *length += count;
    (*buffer)[*length] = '\0';
    return 0;
}

static int encode_utf8(unsigned long code, char *out)
{
    if (code < 0x80) {
        out[0] = (char)code;
        return 1;
    }
    if (code < 0x800) {
        out[0] = (char)(0xC0 | (code >> 6));
        out[1] = (char)(0x80 | (code & 0x3F));
        return 2;
    }
    if (code < 0x10000) {     /* a lone surrogate is kept as its 3-byte form (WTF-8) */
        out[0] = (char)(0xE0 | (code >> 12));
        out[1] = (char)(0x80 | ((code >> 6) & 0x3F));
        out[2] = (char)(0x80 | (code & 0x3F));
        return 3;
    }
    out[0] = (char)(0xF0 | (code >> 18));
    out[1] = (char)(0x80 | ((code >> 12) & 0x3F));
    out[2] = (char)(0x80 | ((code >> 6) & 0x3F));
    out[3] = (char)(0x80 | (code & 0x3F));
    return 4;
}

/* Four hex digits at text[at..at+4) -> *code; 1 if one is not a hex digit. */
static int hex4(const char *text, size_t at, unsigned long *code)
{
    size_t i;
    *code = 0;
    for (i = at; i < at + 4; i++) {
        char c = text[i];
        int digit = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
                    : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
        if (digit < 0) {
            return 1;
        }
        *code = *code * 16 + (unsigned long)digit;
    }
    return 0;
}

/* scanstring: the string whose opening quote is at begin - 1; *next after its closing one. */
static int scan_string(Scanner *scanner, size_t begin, JsonValue *out, size_t *next)
{
    const char *text = scanner->text;
    size_t len = scanner->length, at = begin, capacity = 0;
    char *buffer = NULL, bytes[4];
    *out = EMPTY_VALUE;
    out->kind = JSON_STRING;
    for (;;) {
        size_t chunk = at;
        unsigned long code;
        while (at < len && text[at] != '"' && text[at] != '\\') {
            if ((unsigned char)text[at] <= 0x1F) {
                free(buffer);
                return fail(scanner, "Invalid control character at", at);
            }
            at++;
        }
        if (append(&buffer, &out->length, &capacity, text + chunk, at - chunk)) {
            free(buffer);
            return fail(scanner, "out of memory", at);
        }
        if (at >= len) {
            free(buffer);
            return fail(scanner, "Unterminated string starting at", begin - 1);
        }
        if (text[at] == '"') {
            break;
        }
        at++;                                    /* past the backslash */
        if (at >= len) {
            free(buffer);
            return fail(scanner, "Unterminated string starting at", begin - 1);
        }
        if (text[at] != 'u') {
            const char *plain = strchr("\"\\/bfnrt", text[at]);
            static const char decoded[] = "\"\\/\b\f\n\r\t";
            if (plain == NULL || text[at] == '\0') {
                free(buffer);
                return fail(scanner, "Invalid \\escape", at - 1);
            }
            bytes[0] = decoded[plain - "\"\\/bfnrt"];
            at++;
            if (append(&buffer, &out->length, &capacity, bytes, 1)) {
                free(buffer);
                return fail(scanner, "out of memory", at);
            }
            continue;
        }
        /* \uXXXX at `at` (the 'u'); as _json.c: needs a character after the four digits */
        if (at + 1 + 4 >= len || hex4(text, at + 1, &code)) {
            free(buffer);
            return fail(scanner, "Invalid \\uXXXX escape", at);
        }
        at += 5;
        if (code >= 0xD800 && code <= 0xDBFF && at + 6 < len && text[at] == '\\'
            && text[at + 1] == 'u') {
            unsigned long low;
            if (hex4(text, at + 2, &low)) {
                free(buffer);
                return fail(scanner, "Invalid \\uXXXX escape", at + 1);
            }
            if (low >= 0xDC00 && low <= 0xDFFF) {
                code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
                at += 6;
            }
        }
        if (append(&buffer, &out->length, &capacity, bytes, (size_t)encode_utf8(code, bytes))) {
            free(buffer);
            return fail(scanner, "out of memory", at);
        }
    }
    if (buffer == NULL && append(&buffer, &out->length, &capacity, "", 0)) {
        return fail(scanner, "out of memory", at);
    }
    out->text = buffer;
    *next = at + 1;
    return 0;
}

static int scan_value(Scanner *scanner, size_t at, int depth, JsonValue *out, size_t *next);

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
static int scan_container(Scanner *scanner, size_t at, int depth, int object, JsonValue *out,
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
                    return fail(scanner, "Expecting property name enclosed in double quotes",
                                at);
                }
                if (scan_string(scanner, at + 1, &key, &at)) {
                    return 1;
                }
                at = skip_space(scanner, at);
                if (at >= len || text[at] != ':') {
                    json_value_free(&key);
                    return fail(scanner, "Expecting ':' delimiter", at);
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
                return fail(scanner, "out of memory", at);
            }
            at = skip_space(scanner, at);
            if (at < len && text[at] == close) {
                break;
            }
            if (at >= len || text[at] != ',') {
                return fail(scanner, "Expecting ',' delimiter", at);
            }
            at = skip_space(scanner, at + 1);
        }
    }
    *next = at + 1;
    return 0;
}

/* Does the literal `word` start at `at`? */
static int literal(const Scanner *scanner, size_t at, const char *word)
{
    size_t n = strlen(word);
    return at + n <= scanner->length && strncmp(scanner->text + at, word, n) == 0;
}

/* _match_number: a number starting at `at` (Expecting value when there is none). */
static int scan_number(Scanner *scanner, size_t at, JsonValue *out, size_t *next)
{
    const char *text = scanner->text;
    size_t len = scanner->length, start = at, digits;
    int is_float = 0;
    *out = EMPTY_VALUE;
    out->kind = JSON_NUMBER;
    if (text[at] == '-' && ++at >= len) {
        return fail(scanner, "Expecting value", start);
    }
    if (text[at] >= '1' && text[at] <= '9') {
        while (++at < len && is_digit(text[at])) {
        }
    } else if (text[at] == '0') {
        at++;
    } else {
        return fail(scanner, "Expecting value", start);
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
        return fail(scanner, "Expecting value", start);
    }
    out->integer = !is_float;
    if (out->integer && out->number == 0.0) {
        out->number = 0.0;        /* int("-0") is 0 */
    }
    out->text = (char *)malloc(at - start + 1);
    if (out->text == NULL) {
        return fail(scanner, "out of memory", start);
    }
    memcpy(out->text, text + start, at - start);
    out->text[at - start] = '\0';
    out->length = at - start;
    *next = at;
    return 0;
}

/* scan_once: the value starting at `at`. */
static int scan_value(Scanner *scanner, size_t at, int depth, JsonValue *out, size_t *next)
{
    *out = EMPTY_VALUE;
    if (at >= scanner->length) {
        return fail(scanner, "Expecting value", at);
    }
    switch (scanner->text[at]) {
    case '"':
        return scan_string(scanner, at + 1, out, next);
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
                return fail(scanner, "out of memory", at);
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

/* Length of the valid UTF-8 prefix of text[0..length). */
static size_t valid_utf8(const unsigned char *text, size_t length)
{
    size_t at = 0;
    while (at < length) {
        unsigned char c = text[at];
        size_t n = c < 0x80 ? 1 : (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3
                   : (c & 0xF8) == 0xF0 ? 4 : 0, i;
        unsigned long code;
        if (n == 0 || at + n > length || (n == 2 && c < 0xC2) || (n == 4 && c > 0xF4)) {
            return at;
        }
        code = n == 1 ? c : (unsigned long)(c & (0x7F >> n));
        for (i = 1; i < n; i++) {
            if ((text[at + i] & 0xC0) != 0x80) {
                return at;
            }
            code = (code << 6) | (text[at + i] & 0x3F);
        }
        if ((n == 3 && code < 0x800) || (n == 4 && (code < 0x10000 || code > 0x10FFFF))) {
            return at;
        }
        at += n;
    }
    return at;
}

int json_text_parse(const char *text, JsonValue *out, char *error, size_t error_size)
{
    Scanner scanner;
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
    valid = valid_utf8((const unsigned char *)text, scanner.length);
    if (valid != scanner.length) {
        snprintf(error, error_size, "invalid UTF-8 at byte %lu", (unsigned long)valid);
        return 1;
    }
    if (scanner.length >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) {
        return fail(&scanner, "Unexpected UTF-8 BOM (decode using utf-8-sig)", 0);
    }
    if (scan_value(&scanner, skip_space(&scanner, 0), 0, out, &at)) {
        json_value_free(out);
        return 1;
    }
    at = skip_space(&scanner, at);
    if (at != scanner.length) {
        json_value_free(out);
        return fail(&scanner, "Extra data", at);
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
