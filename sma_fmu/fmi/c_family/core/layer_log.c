/* Messages to the host's logger, with the pythonfmu FMUs' wording and filtering.
 *
 * Text: "<model> '<instance>': <function>: <why>" (SlaveInterface.log). It reaches the
 * logger as the argument of a "%s" format, never as the format: a '%' in an instance name
 * or a String parameter is printed as it is by every host (FMI 2.0 gives the message as a
 * printf format with arguments).
 * Filtering (as the pythonfmu FMUs' front, fmi/python_family/front/host_log.c): with loggingOn = false
 * the host still gets warnings, discards and errors, unless it switches them off with
 * fmi2SetDebugLogging(false, 0, NULL) or by category; the categories are those of the model
 * description (logStatusWarning, logStatusDiscard, logStatusError, logStatusFatal, logAll).
 * A call returns at least the worst status it logged. */
#include "fp_contract.h"
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log_category.h"
#include "layer.h"

static int category_enabled(const Instance *in, const char *category)
{
    size_t length = strlen(category);
    const char *p = in->categories;
    while (p && *p) {
        const char *end = strchr(p, '\n');
        if ((size_t)(end - p) == length && strncmp(p, category, length) == 0) return 1;
        p = end + 1;
    }
    return 0;
}

static int wanted(const Instance *in, SmaStatus status)
{
    const char *category = log_status_category((int)status);
    if (status >= SMA_WARNING && in->log_problems) return 1;
    return in->log_all || category_enabled(in, "logAll") || category_enabled(in, category);
}

/* Formats and passes on one message; `prefixed`: "<model> '<instance>': " first. */
static void emit(Instance *in, SmaStatus status, int prefixed, const char *format,
                 va_list arguments)
{
    char text[2048];
    int used = 0;
    if (status > in->worst) in->worst = status;
    if (!in->logger || !wanted(in, status)) return;
    if (prefixed) {
        used = snprintf(text, sizeof text, "%s '%s': ", in->model->name, in->name);
        if (used < 0 || (size_t)used >= sizeof text) used = 0;
    }
    vsnprintf(text + used, sizeof text - (size_t)used, format, arguments);
    in->emit(in, status, log_status_category((int)status), text);
}

void layer_log(Instance *in, SmaStatus status, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    emit(in, status, 1, format, arguments);
    va_end(arguments);
}

void layer_plain(Instance *in, SmaStatus status, const char *format, ...)
{
    va_list arguments;
    va_start(arguments, format);
    emit(in, status, 0, format, arguments);
    va_end(arguments);
}

SmaStatus layer_reject(Instance *in, SmaStatus status, const char *function, const char *why)
{
    layer_plain(in, status, "%s: %s", function, why);
    return status;
}

SmaStatus layer_refuse(Instance *in, SmaStatus status, const char *function, const char *why)
{
    layer_log(in, status, "%s: %s", function, why);
    return status;
}

/* Append `category` to the enabled ones (once); 0: out of memory. */
static int enable(Instance *in, const char *category)
{
    size_t old = in->categories ? strlen(in->categories) : 0;
    char *grown;
    if (category_enabled(in, category)) return 1;
    grown = (char *)realloc(in->categories, old + strlen(category) + 2);
    if (!grown) return 0;
    in->categories = grown;
    sprintf(grown + old, "%s\n", category);
    return 1;
}

static void disable(Instance *in, const char *category)
{
    size_t length = strlen(category);
    char *p = in->categories;
    while (p && *p) {
        char *end = strchr(p, '\n');
        if ((size_t)(end - p) == length && strncmp(p, category, length) == 0) {
            memmove(p, end + 1, strlen(end + 1) + 1);
            return;
        }
        p = end + 1;
    }
}

int layer_set_debug_logging(Instance *in, int on, size_t n, const char *const categories[])
{
    size_t i;
    if (n == 0) {
        in->log_all = in->log_problems = on ? 1 : 0;
        free(in->categories);
        in->categories = NULL;
        return 1;
    }
    if (!categories) return 0;
    for (i = 0; i < n; ++i)  /* all checked before anything changes (any name is taken,
                                 as by the pythonfmu FMUs) */
        if (!categories[i] || !layer_valid_utf8(categories[i]))
            return 0;
    for (i = 0; i < n; ++i) {
        const char *category = categories[i];
        if (strcmp(category, "logAll") == 0) in->log_all = on ? 1 : 0;
        if (strcmp(category, "logAll") == 0 || strncmp(category, "logStatus", 9) == 0)
            in->log_problems = on ? 1 : 0;
        if (on) {
            if (!enable(in, category)) return 0;
        } else {
            disable(in, category);
        }
    }
    return 1;
}

int layer_valid_utf8(const char *text)
{
    const unsigned char *p = (const unsigned char *)text;
    while (*p) {
        unsigned char c = *p;
        int extra, i;
        unsigned long code;
        if (c < 0x80) { ++p; continue; }
        if ((c & 0xE0) == 0xC0) { extra = 1; code = c & 0x1Fu; }
        else if ((c & 0xF0) == 0xE0) { extra = 2; code = c & 0x0Fu; }
        else if ((c & 0xF8) == 0xF0) { extra = 3; code = c & 0x07u; }
        else return 0;
        for (i = 1; i <= extra; ++i) {
            if ((p[i] & 0xC0) != 0x80) return 0;
            code = (code << 6) | (p[i] & 0x3Fu);
        }
        if ((extra == 1 && code < 0x80) || (extra == 2 && code < 0x800) ||
            (extra == 3 && (code < 0x10000 || code > 0x10FFFF)) || (code >= 0xD800 && code <= 0xDFFF))
            return 0;
        p += extra + 1;
    }
    return 1;
}

void layer_repr(double value, char *text)
{
    char digits[40], mantissa[24], shown[80];
    int precision, exponent, length;
    const char *e;
    if (isnan(value)) { strcpy(text, "nan"); return; }
    if (isinf(value)) { strcpy(text, value < 0 ? "-inf" : "inf"); return; }
    for (precision = 1; precision <= 17; ++precision) {  /* the shortest that reads back */
        snprintf(digits, sizeof digits, "%.*e", precision - 1, value);
        if (strtod(digits, NULL) == value) break;
    }
    e = strchr(digits, 'e');
    exponent = atoi(e + 1);
    length = (int)(e - digits);
    memcpy(mantissa, digits, (size_t)length);
    mantissa[length] = '\0';
    if (exponent < -4 || exponent >= 16) {  /* repr's scientific form: 1e-05, 1.5e+16 */
        snprintf(shown, sizeof shown, "%se%c%02d", mantissa, exponent < 0 ? '-' : '+', abs(exponent));
    } else {
        snprintf(shown, sizeof shown, "%.*f", precision - 1 - exponent > 0 ? precision - 1 - exponent : 0,
                 value);
        if (!strchr(shown, '.')) strcat(shown, ".0");
    }
    shown[31] = '\0';  /* at most 24 characters: "-1.2345678901234567e-308" */
    strcpy(text, shown);
}
