/*
 * python_version.c - small text helpers the libpython searches share (libpython_posix.c,
 * libpython_windows.c): appending to a message, reading a Python's version and checking it.
 *
 * Below the searches and python_runtime.c: it calls none of them.
 */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "front.h"

void text_append(char* text, size_t size, const char* format, ...)
{
    size_t used = strlen(text);
    if (used + 1 >= size) return;
    va_list args;
    va_start(args, format);
    vsnprintf(text + used, size - used, format, args);
    va_end(args);
}

void python_version(void* get_version, char* version)
{
    const char* (*function)(void);
    *(void**)&function = get_version;
    const char* text = function ? function() : NULL;
    version[0] = '\0';
    if (text) sscanf(text, "%31s", version);
}

int python_version_supported(const char* version, char* why, size_t size)
{
    int major = 0, minor = 0;
    char number[32] = "";
    if (version) sscanf(version, "%31s", number);
    if (sscanf(number, "%d.%d", &major, &minor) == 2 && major == 3 && minor >= PYTHON_MIN_MINOR)
        return 1;
    snprintf(why, size, "Python %s is not supported: this FMU needs Python 3.%d or newer",
             *number ? number : "(of unknown version)", PYTHON_MIN_MINOR);
    return 0;
}
