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
 * On Windows the path is a drive path: file:///C:/dir (or, plain, C:\dir), UTF-8. The URI is
 * read by c_common/file_uri.c, which the C family compiles too: both families take the same
 * locations; this file adds pythonfmu's needs (slavemodule.txt, the forwarded form).
 */
#define _GNU_SOURCE
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "file_uri.h"
#include "front.h"

#ifdef _WIN32
#define FORWARD_PREFIX "file:///"
#else
#define FORWARD_PREFIX "file://"
#endif

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
    char* folder = file_uri_folder(uri, plain_path, err, errlen);
    if (!folder) return NULL;
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

/* The wire digest parameters.json in `resources` records ("sha256:..."), into `out`; "unknown"
 * if it cannot be read (the build writes it as  "wire_digest": "sha256:<64 hex>"). */
static void resources_wire(const char* resources, char* out, size_t size)
{
    char file[PATH_SIZE + 64], text[1024];
    snprintf(out, size, "unknown");
    snprintf(file, sizeof file, "%s/parameters.json", resources);
    FILE* stream = file_open(file, "r");
    if (!stream) return;
    size_t n = fread(text, 1, sizeof text - 1, stream);
    fclose(stream);
    text[n] = '\0';
    const char* start = strstr(text, "\"wire_digest\": \"");
    if (!start) return;
    start += 16;
    const char* end = strchr(start, '"');
    if (end && end - start < (long)size && end - start <= 80)
        snprintf(out, size, "%.*s", (int)(end - start), start);
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
    char wire[96];
    resources_wire(resources, wire, sizeof wire);
    snprintf(err, errlen, "fmuGUID '%s' does not match the guid '%.*s' of %s (its resources "
             "hold the wire %s): the model description and the resources are of different "
             "builds (another parameter file, version or model)", guid, (int)(end - start), start,
             file, wire);
    return 0;
}
