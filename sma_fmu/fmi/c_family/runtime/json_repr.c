/* Python's repr() of loaded JSON values, for messages, and member look-up (json_text.h). */
#include "fp_contract.h"
#include "json_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_number.h"

/* A bounded writer: text past the end is dropped, out stays NUL-terminated. */
typedef struct Writer {
    char *out;
    size_t size;
    size_t at;
} Writer;

static void put(Writer *writer, const char *bytes, size_t count)
{
    size_t room = writer->size - 1 - writer->at;
    if (count > room) {
        count = room;
    }
    memcpy(writer->out + writer->at, bytes, count);
    writer->at += count;
    writer->out[writer->at] = '\0';
}

static void put_text(Writer *writer, const char *text)
{
    put(writer, text, strlen(text));
}

/* Python's str.isprintable() for a code point >= 0xA0: false for the separators, format
 * characters, surrogates and private use it knows without the Unicode database (an
 * approximation: unassigned code points count as printable here). */
static int printable(unsigned long code)
{
    static const unsigned long hidden[][2] = {
        {0xA0, 0xA0}, {0xAD, 0xAD}, {0x600, 0x605}, {0x61C, 0x61C}, {0x6DD, 0x6DD},
        {0x70F, 0x70F}, {0x8E2, 0x8E2}, {0x1680, 0x1680}, {0x180E, 0x180E}, {0x2000, 0x200F},
        {0x2028, 0x202F}, {0x205F, 0x2064}, {0x2066, 0x206F}, {0x3000, 0x3000},
        {0xD800, 0xF8FF}, {0xFEFF, 0xFEFF}, {0xFFF9, 0xFFFB}, {0xF0000, 0x10FFFF}};
    size_t i;
    for (i = 0; i < sizeof hidden / sizeof hidden[0]; i++) {
        if (code >= hidden[i][0] && code <= hidden[i][1]) {
            return 0;
        }
    }
    return 1;
}

/* repr(str): single quotes unless the text holds ' and no ", escapes as Python's. The text
 * is UTF-8 (lone surrogates in their 3-byte form, as json_text.c keeps them). */
static void put_string(Writer *writer, const char *text, size_t length)
{
    char quote = memchr(text, '\'', length) != NULL && memchr(text, '"', length) == NULL ? '"'
                                                                                         : '\'';
    size_t i = 0;
    put(writer, &quote, 1);
    while (i < length) {
        unsigned char c = (unsigned char)text[i];
        size_t n = c < 0x80 ? 1 : c < 0xE0 ? 2 : c < 0xF0 ? 3 : 4, k;
        unsigned long code = n == 1 ? c : (unsigned long)(c & (0x7F >> n));
        char escaped[12];
        for (k = 1; k < n && i + k < length; k++) {
            code = (code << 6) | ((unsigned char)text[i + k] & 0x3Fu);
        }
        if (code == (unsigned char)quote || code == '\\') {
            escaped[0] = '\\';
            escaped[1] = (char)code;
            put(writer, escaped, 2);
        } else if (code == '\t' || code == '\n' || code == '\r') {
            put_text(writer, code == '\t' ? "\\t" : code == '\n' ? "\\n" : "\\r");
        } else if (code < 0x20 || (code >= 0x7F && code < 0xA0)
                   || (code >= 0xA0 && !printable(code))) {
            snprintf(escaped, sizeof escaped, code < 0x100 ? "\\x%02lx" : code < 0x10000
                     ? "\\u%04lx" : "\\U%08lx", code);
            put_text(writer, escaped);
        } else {
            put(writer, text + i, n);
        }
        i += n;
    }
    put(writer, &quote, 1);
}

static void put_value(Writer *writer, const JsonValue *value)
{
    size_t i;
    char number[40];
    switch (value->kind) {
    case JSON_NULL:
        put_text(writer, "None");
        break;
    case JSON_TRUE:
        put_text(writer, "True");
        break;
    case JSON_FALSE:
        put_text(writer, "False");
        break;
    case JSON_NUMBER:
        if (value->integer) {
            /* int(text): the digits as written, "-0" being 0 */
            put_text(writer, strcmp(value->text, "-0") == 0 ? "0" : value->text);
        } else {
            json_float_repr(value->number, number, sizeof number);
            put_text(writer, number);
        }
        break;
    case JSON_STRING:
        put_string(writer, value->text, value->length);
        break;
    case JSON_ARRAY:
    case JSON_OBJECT:
        put_text(writer, value->kind == JSON_ARRAY ? "[" : "{");
        for (i = 0; i < value->count && writer->at + 1 < writer->size; i++) {
            if (i > 0) {
                put_text(writer, ", ");
            }
            if (value->kind == JSON_OBJECT) {
                put_value(writer, &value->keys[i]);
                put_text(writer, ": ");
            }
            put_value(writer, &value->items[i]);
        }
        put_text(writer, value->kind == JSON_ARRAY ? "]" : "}");
        break;
    }
}

void json_value_repr(const JsonValue *value, char *out, size_t size)
{
    Writer writer;
    if (size == 0) {
        return;
    }
    writer.out = out;
    writer.size = size;
    writer.at = 0;
    out[0] = '\0';
    put_value(&writer, value);
}

void json_text_repr(const char *text, size_t length, char *out, size_t size)
{
    Writer writer;
    if (size == 0) {
        return;
    }
    writer.out = out;
    writer.size = size;
    writer.at = 0;
    out[0] = '\0';
    put_string(&writer, text, length);
}

int json_string_is(const JsonValue *key, const char *name)
{
    return key->kind == JSON_STRING && key->length == strlen(name)
           && memcmp(key->text, name, key->length) == 0;
}

const JsonValue *json_object_get(const JsonValue *object, const char *name)
{
    size_t i;
    for (i = 0; object->kind == JSON_OBJECT && i < object->count; i++) {
        if (json_string_is(&object->keys[i], name)) {
            return &object->items[i];
        }
    }
    return NULL;
}

void json_float_repr(double number, char *out, size_t size)
{
    char digits[40], mantissa[24], text[48];
    int precision, exponent = 0, count = 0, negative = 0, i, at = 0, decimal_point;
    double back = 0.0;
    if (size == 0) {
        return;
    }
    if (isnan(number) || isinf(number)) {
        snprintf(out, size, "%s", isnan(number) ? "nan" : (number > 0 ? "inf" : "-inf"));
        return;
    }
    if (number == 0.0) {
        snprintf(out, size, "%s", signbit(number) ? "-0.0" : "0.0");
        return;
    }
    /* the shortest correctly rounded digits that read back to the number (Python's 'r') */
    for (precision = 1; precision <= 17; precision++) {
        snprintf(digits, sizeof digits, "%.*e", precision - 1, number);
        for (i = 0; digits[i] != '\0' && digits[i] != 'e'; i++) {
            if (digits[i] == ',') {
                digits[i] = '.';      /* a host's locale may print a decimal comma */
            }
        }
        count = 0;
        negative = digits[0] == '-';
        for (i = 0; digits[i] != '\0' && digits[i] != 'e'; i++) {
            if (digits[i] >= '0' && digits[i] <= '9' && count < (int)sizeof mantissa - 1) {
                mantissa[count++] = digits[i];
            }
        }
        mantissa[count] = '\0';
        exponent = digits[i] == 'e' ? (int)strtol(digits + i + 1, NULL, 10) : 0;
        snprintf(text, sizeof text, "%s%se%d", negative ? "-" : "", mantissa, exponent - count + 1);
        if (json_number_value(text, strlen(text), &back) == 0 && back == number) {
            break;
        }
    }
    while (count > 1 && mantissa[count - 1] == '0') {
        mantissa[--count] = '\0';
    }
    decimal_point = exponent + 1;     /* value = 0.mantissa * 10^decimal_point */
    if (negative) {
        text[at++] = '-';
    }
    if (decimal_point <= -4 || decimal_point > 16) {
        text[at++] = mantissa[0];
        if (count > 1) {
            text[at++] = '.';
            for (i = 1; i < count; i++) {
                text[at++] = mantissa[i];
            }
        }
        snprintf(text + at, sizeof text - (size_t)at, "e%c%02d", exponent < 0 ? '-' : '+',
                 exponent < 0 ? -exponent : exponent);
    } else if (decimal_point <= 0) {
        text[at++] = '0';
        text[at++] = '.';
        for (i = 0; i < -decimal_point; i++) {
            text[at++] = '0';
        }
        for (i = 0; i < count; i++) {
            text[at++] = mantissa[i];
        }
        text[at] = '\0';
    } else {
        for (i = 0; i < count || i < decimal_point; i++) {
            if (i == decimal_point) {
                text[at++] = '.';
            }
            text[at++] = i < count ? mantissa[i] : '0';
        }
        if (count <= decimal_point) {
            text[at++] = '.';
            text[at++] = '0';
        }
        text[at] = '\0';
    }
    snprintf(out, size, "%s", text);
}
