/*
 * host_log.c - messages to the host's logger.
 *
 * FMI 2.0 passes the message as a printf format. Every '%' of a message is therefore
 * doubled and the message passed with no arguments: a host that formats it (fmusim, the
 * FMI Library, fmpy's log proxy) prints a '%' from an instance name, a String parameter or
 * anything else literally, and a host that takes the text as it is can undo "%%".
 *
 * Filtering follows FMI 2.0 and the Reference FMUs: with loggingOn = false the host still
 * gets warnings, discards and errors ("always log errors"), unless it switches them off
 * with fmi2SetDebugLogging(false, 0, NULL) or by category (logStatusWarning,
 * logStatusDiscard, logStatusError, logStatusFatal, logAll). Other messages need
 * loggingOn or their category enabled. pythonfmu itself always gets loggingOn = true.
 *
 * The slave's messages carry the status of the call: the front returns the worst status
 * the slave logged during a call (see fmi2_exports.c). The slave doubles every '%' itself
 * (pythonfmu alone passes its messages on as formats); the front undoes that before
 * doubling every message the same way.
 */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log_category.h"
#include "front.h"

static int category_enabled(const Instance* in, const char* category)
{
    for (size_t i = 0; i < in->n_categories; ++i)
        if (strcmp(in->categories[i], category) == 0) return 1;
    return 0;
}

static int wanted(const Instance* in, fmi2Status status, const char* category)
{
    if (status >= fmi2Warning && in->log_problems) return 1;
    if (in->log_all) return 1;
    return category_enabled(in, "logAll") || category_enabled(in, category) ||
           category_enabled(in, log_status_category((int)status));
}

void host_log(const Instance* in, fmi2Status status, const char* category, const char* message)
{
    if (!in->host_logger) return;
    if (!category || !*category) category = log_status_category((int)status);
    if (!wanted(in, status, category)) return;
    if (!message) message = "";
    size_t length = strlen(message), percents = 0;
    for (const char* p = message; *p; ++p) percents += *p == '%';
    char* format = (char*)malloc(length + percents + 1);
    if (!format) return;
    char* out = format;
    for (const char* p = message; *p; ++p) {
        *out++ = *p;
        if (*p == '%') *out++ = '%';
    }
    *out = '\0';
    in->host_logger(in->host_environment, in->name ? in->name : "?", status, category, format);
    free(format);
}

void host_logf(const Instance* in, fmi2Status status, const char* format, ...)
{
    char text[4096];
    va_list args;
    va_start(args, format);
    vsnprintf(text, sizeof text, format, args);
    va_end(args);
    host_log(in, status, NULL, text);
}

/* "%%" -> "%" in place. */
static void undouble_percent(char* text)
{
    char* out = text;
    for (const char* p = text; *p; ++p) {
        *out++ = *p;
        if (p[0] == '%' && p[1] == '%') ++p;
    }
    *out = '\0';
}

/* The logger pythonfmu gets. pythonfmu passes its message as the format with no
 * arguments (Fmi2Logger::debugLog), so `message` is the plain text. */
void front_logger(fmi2ComponentEnvironment env, fmi2String instance_name, fmi2Status status,
                  fmi2String category, fmi2String message, ...)
{
    Instance* in = (Instance*)env;
    (void)instance_name;
    if (!in || !message) return;
    int from_slave = category && *category && strcmp(category, "cppfmu") != 0;
    if (!from_slave) {
        host_log(in, status, NULL, message);
        return;
    }
    if (status > in->logged_status && status <= fmi2Error) in->logged_status = status;
    char* text = strdup(message);
    if (!text) return;
    undouble_percent(text);
    host_log(in, status, category, text);
    free(text);
}

static void clear_categories(Instance* in)
{
    for (size_t i = 0; i < in->n_categories; ++i) free(in->categories[i]);
    in->n_categories = 0;
}

/* fmi2SetDebugLogging; returns 0 for a bad argument. */
int set_debug_logging(Instance* in, fmi2Boolean on, size_t n, const fmi2String categories[])
{
    if (n == 0) {
        in->log_all = in->log_problems = on ? 1 : 0;
        clear_categories(in);
        return 1;
    }
    if (!categories) return 0;
    for (size_t i = 0; i < n; ++i) {
        const char* category = categories[i];
        if (!category || !valid_utf8(category)) return 0;
        if (strcmp(category, "logAll") == 0) in->log_all = on ? 1 : 0;
        if (strcmp(category, "logAll") == 0 || strncmp(category, "logStatus", 9) == 0)
            in->log_problems = on ? 1 : 0;
        size_t k = 0;
        while (k < in->n_categories && strcmp(in->categories[k], category) != 0) ++k;
        if (on && k == in->n_categories) {
            char** grown = (char**)realloc(in->categories, (in->n_categories + 1) * sizeof *grown);
            char* copy = strdup(category);
            if (!grown || !copy) {
                free(copy);
                if (grown) in->categories = grown;
                return 0;
            }
            in->categories = grown;
            in->categories[in->n_categories++] = copy;
        } else if (!on && k < in->n_categories) {
            free(in->categories[k]);
            in->categories[k] = in->categories[--in->n_categories];
        }
    }
    return 1;
}

/* 1 if `text` is well-formed UTF-8 (what pythonfmu needs to build a Python str). */
int valid_utf8(const char* text)
{
    const unsigned char* p = (const unsigned char*)text;
    while (*p) {
        unsigned char c = *p;
        int extra;
        unsigned int code;
        if (c < 0x80) { ++p; continue; }
        else if ((c & 0xE0) == 0xC0) { extra = 1; code = c & 0x1F; }
        else if ((c & 0xF0) == 0xE0) { extra = 2; code = c & 0x0F; }
        else if ((c & 0xF8) == 0xF0) { extra = 3; code = c & 0x07; }
        else return 0;
        for (int i = 1; i <= extra; ++i) {
            if ((p[i] & 0xC0) != 0x80) return 0;
            code = (code << 6) | (p[i] & 0x3F);
        }
        if ((extra == 1 && code < 0x80) || (extra == 2 && code < 0x800) ||
            (extra == 3 && (code < 0x10000 || code > 0x10FFFF)) || (code >= 0xD800 && code <= 0xDFFF))
            return 0;
        p += extra + 1;
    }
    return 1;
}
