/* Python's repr() of loaded JSON values, for messages, and member look-up (json_text.h). */
#include "json_text.h"

#include <stdio.h>
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

/* repr(str): single quotes unless the text holds ' and no ", escapes as Python's. */
static void put_string(Writer *writer, const char *text, size_t length)
{
    char quote = memchr(text, '\'', length) != NULL && memchr(text, '"', length) == NULL ? '"'
                                                                                         : '\'';
    size_t i;
    put(writer, &quote, 1);
    for (i = 0; i < length; i++) {
        unsigned char c = (unsigned char)text[i];
        char escaped[8];
        if (c == (unsigned char)quote || c == '\\') {
            escaped[0] = '\\';
            escaped[1] = (char)c;
            put(writer, escaped, 2);
        } else if (c == '\t' || c == '\n' || c == '\r') {
            put_text(writer, c == '\t' ? "\\t" : c == '\n' ? "\\n" : "\\r");
        } else if (c < 0x20 || c == 0x7F) {
            snprintf(escaped, sizeof escaped, "\\x%02x", c);
            put_text(writer, escaped);
        } else if (c == 0xC2 && i + 1 < length && (unsigned char)text[i + 1] <= 0xA0) {
            /* U+0080..U+00A0 are not printable: \x80 .. \xa0 */
            snprintf(escaped, sizeof escaped, "\\x%02x", (unsigned char)text[++i]);
            put_text(writer, escaped);
        } else if (c == 0xED && i + 2 < length && (unsigned char)text[i + 1] >= 0xA0) {
            /* a lone surrogate (kept by json_text.c as its 3-byte form): \udXXX */
            unsigned code = 0xD000u | (((unsigned char)text[i + 1] & 0x3Fu) << 6)
                            | ((unsigned char)text[i + 2] & 0x3Fu);
            snprintf(escaped, sizeof escaped, "\\u%04x", code);
            put_text(writer, escaped);
            i += 2;
        } else {
            put(writer, text + i, 1);
        }
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
