/*
 * resource_uri.c - checking fmuResourceLocation before pythonfmu sees it.
 *
 * pythonfmu 0.7.0 deletes the first "file://" it finds, turns "%20" into a space and
 * passes the rest on as a path; if slavemodule.txt or the module cannot be read there it
 * calls a NULL Python object (SIGSEGV), and a NULL location aborts. The front accepts
 * file:///abs, file:/abs and file://localhost/abs (percent-decoded) and, with a warning, a
 * plain absolute path; it refuses anything else with a logged error, and checks that the
 * folder holds the slave module named in slavemodule.txt. pythonfmu gets "file://" + path
 * (on Windows "file:///" + "C:/...": pythonfmu's Windows build cuts 8 characters).
 * On Windows the path is a drive path: file:///C:/dir (or, plain, C:\dir), UTF-8.
 */
#define _GNU_SOURCE
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"

#ifdef _WIN32
#define FORWARD_PREFIX "file:///"
#else
#define FORWARD_PREFIX "file://"
#endif

static int same_text(const char* a, const char* b, size_t n) /* ASCII, ignoring case */
{
    for (size_t i = 0; i < n; ++i)
        if (tolower((unsigned char)a[i]) != tolower((unsigned char)b[i])) return 0;
    return 1;
}

#ifdef _WIN32
/* A drive path, "C:/" or "C:\\". */
static int drive_path(const char* path)
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

/* The path part of `uri` (after the scheme and an empty or "localhost" authority), or NULL. */
static const char* uri_path(const char* uri, char* err, size_t errlen, size_t* length,
                            int* plain_path)
{
#ifdef _WIN32
    int plain = drive_path(uri);
#else
    int plain = uri[0] == '/';
#endif
    if (plain) { /* a plain absolute path, not a URI: pythonfmu took it, so do we */
        *plain_path = 1;
        *length = strlen(uri);
        return uri;
    }
    if (!same_text(uri, "file:", 5)) {
        snprintf(err, errlen, "fmuResourceLocation '%s' is not a file: URI", uri);
        return NULL;
    }
    const char* p = uri + 5;
    if (p[0] == '/' && p[1] == '/') { /* an authority */
        const char* host = p + 2;
        const char* end = strchr(host, '/');
        size_t n = end ? (size_t)(end - host) : strlen(host);
        if (n != 0 && !(n == 9 && same_text(host, "localhost", 9))) {
            snprintf(err, errlen, "fmuResourceLocation '%s' names host '%.*s'; only local files "
                     "are supported", uri, (int)n, host);
            return NULL;
        }
        if (!end) {
            snprintf(err, errlen, "fmuResourceLocation '%s' has no path", uri);
            return NULL;
        }
        p = end;
    }
    if (*p != '/') {
        snprintf(err, errlen, "fmuResourceLocation '%s' is not an absolute path", uri);
        return NULL;
    }
#ifdef _WIN32
    if (!drive_path(p + 1)) {
        snprintf(err, errlen, "fmuResourceLocation '%s' does not name a drive (file:///C:/...)", uri);
        return NULL;
    }
    ++p; /* "/C:/dir" is the drive path "C:/dir" */
#endif
    *length = strcspn(p, "?#"); /* query and fragment are not part of the path */
    return p;
}

/* malloc'd decoded copy of path[0:length], or NULL (bad escape). */
static char* decode(const char* path, size_t length, int percent_escapes)
{
    char* out = (char*)malloc(length + 1);
    if (!out) return NULL;
    size_t j = 0;
    for (size_t i = 0; i < length; ++i) {
        if (path[i] == '%' && percent_escapes) {
            int high = i + 2 < length ? hex_value(path[i + 1]) : -1;
            int low = i + 2 < length ? hex_value(path[i + 2]) : -1;
            if (high < 0 || low < 0 || (high == 0 && low == 0)) {
                free(out);
                return NULL;
            }
            out[j++] = (char)(high * 16 + low);
            i += 2;
        } else {
            out[j++] = path[i];
        }
    }
    out[j] = '\0';
    while (j > 1 && out[j - 1] == '/') out[--j] = '\0';
    return out;
}

/* 0 with err set unless `folder` is the resources folder of a pythonfmu FMU. */
static int is_resources_folder(const char* folder, const char* uri, char* err, size_t errlen)
{
    if (!is_directory(folder)) {
        snprintf(err, errlen, "resource folder '%s' (from fmuResourceLocation '%s') does not exist",
                 folder, uri);
        return 0;
    }
    char file[PATH_SIZE + 300], module[256] = "";
    snprintf(file, sizeof file, "%s/slavemodule.txt", folder);
    FILE* stream = file_open(file, "r");
    if (!stream || !fgets(module, sizeof module, stream)) {
        if (stream) fclose(stream);
        snprintf(err, errlen, "'%s' is missing or empty: not the resources folder of this FMU", file);
        return 0;
    }
    fclose(stream);
    module[strcspn(module, "\r\n")] = '\0';
    snprintf(file, sizeof file, "%s/%s.py", folder, module);
    if (!*module || !is_readable_file(file)) {
        snprintf(err, errlen, "the slave module '%s' named in slavemodule.txt is missing", file);
        return 0;
    }
    return 1;
}

char* resource_uri_for_pythonfmu(const char* uri, char* err, size_t errlen, char** path_out,
                                 int* plain_path)
{
    if (!uri) { snprintf(err, errlen, "fmuResourceLocation is NULL"); return NULL; }
    if (!*uri) { snprintf(err, errlen, "fmuResourceLocation is empty"); return NULL; }
    if (!valid_utf8(uri)) { snprintf(err, errlen, "fmuResourceLocation is not UTF-8"); return NULL; }
    size_t length = 0;
    const char* path = uri_path(uri, err, errlen, &length, plain_path);
    if (!path) return NULL;
    char* folder = decode(path, length, !*plain_path);
    if (!folder) {
        snprintf(err, errlen, "fmuResourceLocation '%s' has a bad percent escape", uri);
        return NULL;
    }
    if (!valid_utf8(folder) || strstr(folder, "%20") || strstr(folder, "file://") ||
        strlen(folder) >= PATH_SIZE) {
        snprintf(err, errlen, "resource folder '%s' is not UTF-8, too long or contains '%%20' or "
                 "'file://', which pythonfmu cannot handle", folder);
        free(folder);
        return NULL;
    }
    if (!is_resources_folder(folder, uri, err, errlen)) {
        free(folder);
        return NULL;
    }
#ifdef _WIN32
    for (char* q = folder; *q; ++q)
        if (*q == '\\') *q = '/';
#endif
    char* forwarded = (char*)malloc(strlen(folder) + sizeof FORWARD_PREFIX);
    if (!forwarded) {
        free(folder);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    strcpy(forwarded, FORWARD_PREFIX);
    strcat(forwarded, folder);
    *path_out = folder;
    return forwarded;
}

int guid_matches(const char* resources, const char* guid, char* err, size_t errlen)
{
    char file[PATH_SIZE + 64];
    snprintf(file, sizeof file, "%s/../modelDescription.xml", resources);
    FILE* stream = file_open(file, "r");
    if (!stream) return 1; /* not unpacked in the standard layout: nothing to compare with */
    char head[8192];
    size_t n = fread(head, 1, sizeof head - 1, stream);
    fclose(stream);
    head[n] = '\0';
    const char* start = strstr(head, " guid=\"");
    if (!start) return 1;
    start += 7;
    const char* end = strchr(start, '"');
    if (!end) return 1;
    if (strlen(guid) == (size_t)(end - start) && strncmp(start, guid, (size_t)(end - start)) == 0)
        return 1;
    snprintf(err, errlen, "fmuGUID '%s' does not match the guid '%.*s' of %s", guid,
             (int)(end - start), start, file);
    return 0;
}
