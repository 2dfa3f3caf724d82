/* JSON strings for json_text.c: CPython's scanstring (strict), UTF-8 in and out, and the
 * decoder's error positions (see json_string.h). */
#include "fp_contract.h"
#include "json_string.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const JsonValue EMPTY_VALUE;

/* Python's JSONDecodeError text: "<what>: line L column C (char N)", N in characters. */
int json_fail(JsonScanner *scanner, const char *what, size_t at)
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
int json_scan_string(JsonScanner *scanner, size_t begin, JsonValue *out, size_t *next)
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
                return json_fail(scanner, "Invalid control character at", at);
            }
            at++;
        }
        if (append(&buffer, &out->length, &capacity, text + chunk, at - chunk)) {
            free(buffer);
            return json_fail(scanner, "out of memory", at);
        }
        if (at >= len) {
            free(buffer);
            return json_fail(scanner, "Unterminated string starting at", begin - 1);
        }
        if (text[at] == '"') {
            break;
        }
        at++;                                    /* past the backslash */
        if (at >= len) {
            free(buffer);
            return json_fail(scanner, "Unterminated string starting at", begin - 1);
        }
        if (text[at] != 'u') {
            const char *plain = strchr("\"\\/bfnrt", text[at]);
            static const char decoded[] = "\"\\/\b\f\n\r\t";
            if (plain == NULL || text[at] == '\0') {
                free(buffer);
                return json_fail(scanner, "Invalid \\escape", at - 1);
            }
            bytes[0] = decoded[plain - "\"\\/bfnrt"];
            at++;
            if (append(&buffer, &out->length, &capacity, bytes, 1)) {
                free(buffer);
                return json_fail(scanner, "out of memory", at);
            }
            continue;
        }
        /* \uXXXX at `at` (the 'u'); as _json.c: needs a character after the four digits */
        if (at + 1 + 4 >= len || hex4(text, at + 1, &code)) {
            free(buffer);
            return json_fail(scanner, "Invalid \\uXXXX escape", at);
        }
        at += 5;
        if (code >= 0xD800 && code <= 0xDBFF && at + 6 < len && text[at] == '\\'
            && text[at + 1] == 'u') {
            unsigned long low;
            if (hex4(text, at + 2, &low)) {
                free(buffer);
                return json_fail(scanner, "Invalid \\uXXXX escape", at + 1);
            }
            if (low >= 0xDC00 && low <= 0xDFFF) {
                code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
                at += 6;
            }
        }
        if (append(&buffer, &out->length, &capacity, bytes, (size_t)encode_utf8(code, bytes))) {
            free(buffer);
            return json_fail(scanner, "out of memory", at);
        }
    }
    if (buffer == NULL && append(&buffer, &out->length, &capacity, "", 0)) {
        return json_fail(scanner, "out of memory", at);
    }
    out->text = buffer;
    *next = at + 1;
    return 0;
}

/* Length of the valid UTF-8 prefix of text[0..length). */
size_t json_valid_utf8(const unsigned char *text, size_t length)
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

