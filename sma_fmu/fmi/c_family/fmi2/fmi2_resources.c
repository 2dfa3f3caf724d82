/* fmuResourceLocation -> the resources folder, as the pythonfmu FMUs' front takes it
 * (fmi/native/resource_uri.c, which is tied to pythonfmu's layout: slavemodule.txt):
 * file:///abs, file:/abs and file://localhost/abs, percent-decoded, and with a warning a
 * plain absolute path; anything else is refused with the reason. On Windows the path is a
 * drive path (file:///C:/dir). The folder must exist and hold the FMU's parameters.json. */
#ifndef _WIN32
#define _POSIX_C_SOURCE 200809L  /* stat() */
#endif
#include "fp_contract.h"
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fmi2_layer.h"

#ifdef _WIN32
#define IS_FOLDER(mode) (((mode) & _S_IFMT) == _S_IFDIR)
#define IS_REGULAR(mode) (((mode) & _S_IFMT) == _S_IFREG)
#else
#define IS_FOLDER(mode) S_ISDIR(mode)
#define IS_REGULAR(mode) S_ISREG(mode)
#endif

static int same_text(const char *a, const char *b, size_t n)  /* ASCII, ignoring case */
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (tolower((unsigned char)a[i]) != tolower((unsigned char)b[i])) return 0;
    return 1;
}

#ifdef _WIN32
static int drive_path(const char *path)
{
    return isalpha((unsigned char)path[0]) && path[1] == ':' && (path[2] == '/' || path[2] == '\\');
}
#endif

static int hex_value(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* The path part of `uri` and its length, or NULL with why set. */
static const char *uri_path(const char *uri, size_t *length, int *plain, char *why, size_t size)
{
    const char *p;
#ifdef _WIN32
    *plain = drive_path(uri);
#else
    *plain = uri[0] == '/';
#endif
    if (*plain) {
        *length = strlen(uri);
        return uri;
    }
    if (!same_text(uri, "file:", 5)) {
        snprintf(why, size, "fmuResourceLocation '%.300s' is not a file: URI", uri);
        return NULL;
    }
    p = uri + 5;
    if (p[0] == '/' && p[1] == '/') {  /* an authority: empty or localhost */
        const char *host = p + 2, *end = strchr(host, '/');
        size_t n = end ? (size_t)(end - host) : strlen(host);
        if (n != 0 && !(n == 9 && same_text(host, "localhost", 9))) {
            snprintf(why, size, "fmuResourceLocation '%.300s' names a host; only local files are "
                     "supported", uri);
            return NULL;
        }
        if (!end) {
            snprintf(why, size, "fmuResourceLocation '%.300s' has no path", uri);
            return NULL;
        }
        p = end;
    }
    if (*p != '/') {
        snprintf(why, size, "fmuResourceLocation '%.300s' is not an absolute path", uri);
        return NULL;
    }
#ifdef _WIN32
    if (!drive_path(p + 1)) {
        snprintf(why, size, "fmuResourceLocation '%.300s' does not name a drive (file:///C:/...)", uri);
        return NULL;
    }
    ++p;
#endif
    *length = strcspn(p, "?#");
    return p;
}

/* Is `folder` an unpacked FMU's resources folder? Every FMU of this project ships
 * parameters.json there (the pythonfmu family's front asks for its slave module), so a
 * location such as file:///tmp is refused instead of silently running without the FMU's
 * files (its packed start_values.json among them). */
static int owns_folder(const char *folder, const char *uri, char *why, size_t size)
{
    struct stat info;
    char path[4200];
    snprintf(path, sizeof path, "%s/parameters.json", folder);
    if (stat(path, &info) == 0 && IS_REGULAR(info.st_mode)) return 1;
    snprintf(why, size, "resource folder '%.300s' (from fmuResourceLocation '%.300s') is not this "
             "FMU's resources folder: it holds no parameters.json", folder, uri);
    return 0;
}

int layer_resource_folder(const char *uri, char **folder, int *plain, char *why, size_t size)
{
    size_t length = 0, i, j = 0;
    const char *path;
    char *out;
    struct stat info;
    if (!uri) { snprintf(why, size, "fmuResourceLocation is NULL"); return 0; }
    if (!*uri) { snprintf(why, size, "fmuResourceLocation is empty"); return 0; }
    if (!layer_valid_utf8(uri)) { snprintf(why, size, "fmuResourceLocation is not UTF-8"); return 0; }
    path = uri_path(uri, &length, plain, why, size);
    if (!path) return 0;
    out = (char *)malloc(length + 1);
    if (!out) { snprintf(why, size, "out of memory"); return 0; }
    for (i = 0; i < length; ++i) {
        if (path[i] == '%' && !*plain) {
            int high = i + 2 < length ? hex_value(path[i + 1]) : -1;
            int low = i + 2 < length ? hex_value(path[i + 2]) : -1;
            if (high < 0 || low < 0 || (high == 0 && low == 0)) {
                free(out);
                snprintf(why, size, "fmuResourceLocation '%.300s' has a bad percent escape", uri);
                return 0;
            }
            out[j++] = (char)(high * 16 + low);
            i += 2;
        } else {
            out[j++] = path[i];
        }
    }
    out[j] = '\0';
    while (j > 1 && (out[j - 1] == '/' || out[j - 1] == '\\')) out[--j] = '\0';
    if (!layer_valid_utf8(out) || stat(out, &info) != 0 || !IS_FOLDER(info.st_mode)) {
        snprintf(why, size, "resource folder '%.300s' (from fmuResourceLocation '%.300s') does not "
                 "exist", out, uri);
        free(out);
        return 0;
    }
    if (!owns_folder(out, uri, why, size)) {
        free(out);
        return 0;
    }
    *folder = out;
    return 1;
}
