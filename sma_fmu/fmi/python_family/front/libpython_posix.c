/*
 * libpython_posix.c - finding the Python the backend runs in, on Linux.
 *
 * pythonfmu's binary does not link libpython: it expects the Python C API in the global
 * symbol scope. A Python host (fmpy, libcosimpy, ecospy) has it already, and a second
 * libpython must never be loaded into such a process. A C host has none: then the front
 * loads one with RTLD_GLOBAL, trying in turn
 *   1. $SMA_FMU_LIBPYTHON (and nothing else when it is set);
 *   2. the library of the Python that built the FMU (SMA_FRONT_LIBPYTHON, recorded at build
 *      time), then its soname through the library search path;
 *   3. any libpython3.X of Python 3.PYTHON_MIN_MINOR or newer, newest first: its soname
 *      through the library search path (LD_LIBRARY_PATH, ld.so.cache, /lib, /usr/lib), and
 *      the files in LD_LIBRARY_PATH and the standard folders (STANDARD_FOLDERS).
 * Every Python, the process's own too, must be 3.PYTHON_MIN_MINOR or newer.
 */
#ifndef _WIN32
#define _GNU_SOURCE
#include <dirent.h>
#include <dlfcn.h>
#include <limits.h>
#include <link.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"

#ifndef SMA_FRONT_LIBPYTHON
#define SMA_FRONT_LIBPYTHON "" /* absolute path of the build's libpython */
#endif
#ifndef SMA_FRONT_LIBPYTHON_SONAME
#define SMA_FRONT_LIBPYTHON_SONAME "libpython3.so"
#endif
#if defined(__x86_64__)
#define MULTIARCH "x86_64-linux-gnu"
#elif defined(__aarch64__)
#define MULTIARCH "aarch64-linux-gnu"
#else
#define MULTIARCH "unknown-linux-gnu"
#endif

static const char* const STANDARD_FOLDERS[] = {
    "/usr/local/lib", "/usr/local/lib64", "/usr/lib/" MULTIARCH, "/lib/" MULTIARCH,
    "/usr/lib64", "/lib64", "/usr/lib", "/lib", NULL};

void* python_symbol(const char* name) { return dlsym(RTLD_DEFAULT, name); }

int python_library_file(char* path, size_t size)
{
    Dl_info info;
    void* function = python_symbol("Py_IsInitialized");
    if (!function || !dladdr(function, &info) || !info.dli_fname || info.dli_fname[0] != '/')
        return 0;
    snprintf(path, size, "%s", info.dli_fname);
    return 1;
}

/* dl_iterate_phdr callback: the first mapped libpython, if any. */
static int find_mapped_libpython(struct dl_phdr_info* info, size_t size, void* found)
{
    (void)size;
    const char* name = info->dlpi_name;
    const char* base = name ? strrchr(name, '/') : NULL;
    base = base ? base + 1 : name;
    if (base && strncmp(base, "libpython", 9) == 0) {
        snprintf((char*)found, PATH_MAX, "%s", name);
        return 1;
    }
    return 0;
}

/* 1 if the process's Python is usable (global scope), else 0 with load_error set. */
static int check_process_python(const char* how)
{
    char version[32], why[256];
    python_version(python_symbol("Py_GetVersion"), version);
    if (!python_version_supported(version, why, sizeof why)) {
        snprintf(load_error, sizeof load_error, "the Python in this process: %s", why);
        return 0;
    }
    snprintf(load_info, sizeof load_info, "%s (Python %s)", how, version);
    return 1;
}

/* Load `path` globally if it is a libpython of a supported version. 1: loaded; else the
 * reason is appended to `tried` (unless quiet and not found), after label and path (only
 * the reason if label is NULL), and 0 returned. */
static int try_libpython(const char* path, const char* label, char* tried, size_t size, int quiet)
{
    if (!path || !*path) return 0;
    const char* name = label ? path : "";
    const char* colon = label ? ": " : "";
    if (!label) label = "";
    char reason[512];
    void* handle = library_open(path, 1, 0, reason, sizeof reason);
    if (!handle) {
        int missing = strstr(reason, "No such file") != NULL;
        if (!(quiet && missing))
            text_append(tried, size, "; %s%s%s%s", label, name, colon, missing ? "not found" : reason);
        return 0;
    }
    char version[32], why[256];
    void* get_version = dlsym(handle, "Py_GetVersion");
    python_version(get_version, version);
    if (!dlsym(handle, "Py_IsInitialized") || !get_version) {
        text_append(tried, size, "; %s%s%snot a libpython (no Py_IsInitialized)", label, name, colon);
        dlclose(handle);
        return 0;
    }
    if (!python_version_supported(version, why, sizeof why)) {
        text_append(tried, size, "; %s%s%s%s", label, name, colon, why);
        dlclose(handle);
        return 0;
    }
    Dl_info info;
    const char* file = dladdr(dlsym(handle, "Py_IsInitialized"), &info) && info.dli_fname
                           ? info.dli_fname : path;
    snprintf(load_info, sizeof load_info, "loaded libpython %s (Python %s)", file, version);
    return 1;
}

/* Files libpython3.<minor>.so.1.0 or libpython3.<minor>.so in `folder`, minor >= MIN. */
static void scan_folder(const char* folder, char found[][PATH_MAX], int* minors, int* count, int max)
{
    DIR* dir = opendir(folder);
    if (!dir) return;
    struct dirent* entry;
    while ((entry = readdir(dir)) && *count < max) {
        int minor = 0, end = 0;
        const char* name = entry->d_name;
        if (sscanf(name, "libpython3.%d.so%n", &minor, &end) != 1 || minor < PYTHON_MIN_MINOR ||
            minor > PYTHON_MAX_MINOR || !(name[end] == '\0' || strcmp(name + end, ".1.0") == 0))
            continue;
        snprintf(found[*count], PATH_MAX, "%s/%s", folder, name);
        minors[(*count)++] = minor;
    }
    closedir(dir);
}

/* Step 3: the newest libpython 3.MIN+ in the standard places; 1 if one was loaded. */
static int try_any_libpython(char* tried, size_t size)
{
    enum { MAX_FOUND = 64 };
    static char found[MAX_FOUND][PATH_MAX];
    int minors[MAX_FOUND], count = 0;
    char folders[PATH_SIZE] = "";
    char library_path[PATH_SIZE];
    if (environment("LD_LIBRARY_PATH", library_path, sizeof library_path)) {
        for (char* folder = strtok(library_path, ":"); folder; folder = strtok(NULL, ":")) {
            scan_folder(folder, found, minors, &count, MAX_FOUND);
            text_append(folders, sizeof folders, "%s, ", folder);
        }
    }
    for (int i = 0; STANDARD_FOLDERS[i]; ++i) {
        scan_folder(STANDARD_FOLDERS[i], found, minors, &count, MAX_FOUND);
        text_append(folders, sizeof folders, "%s%s", STANDARD_FOLDERS[i], STANDARD_FOLDERS[i + 1] ? ", " : "");
    }
    for (int minor = PYTHON_MAX_MINOR; minor >= PYTHON_MIN_MINOR; --minor) {
        char soname[64];
        snprintf(soname, sizeof soname, "libpython3.%d.so.1.0", minor);
        if (try_libpython(soname, "", tried, size, 1)) return 1;
        for (int i = 0; i < count; ++i)
            if (minors[i] == minor && try_libpython(found[i], "", tried, size, 1)) return 1;
    }
    text_append(tried, size, "; libpython3.%d.so.1.0 to libpython3.%d.so.1.0 through the library "
           "search path and in %s: none", PYTHON_MAX_MINOR, PYTHON_MIN_MINOR, folders);
    return 0;
}

int load_libpython(void)
{
    if (dlsym(RTLD_DEFAULT, "Py_IsInitialized"))
        return check_process_python("the process already has Python (global scope)");
    char mapped[PATH_MAX] = "";
    if (dl_iterate_phdr(find_mapped_libpython, mapped) && mapped[0]) {
        /* mapped with RTLD_LOCAL: promote that same copy to the global scope */
        if (dlopen(mapped, RTLD_NOW | RTLD_GLOBAL | RTLD_NOLOAD) &&
            dlsym(RTLD_DEFAULT, "Py_IsInitialized")) {
            char how[PATH_MAX + 64];
            snprintf(how, sizeof how, "made the process's %s global", mapped);
            return check_process_python(how);
        }
        snprintf(load_error, sizeof load_error, "the process has %s loaded privately and it "
                 "could not be made global; not loading a second libpython", mapped);
        return 0;
    }
    char tried[sizeof load_error - 512] = "";
    char chosen[PATH_SIZE];
    if (environment("SMA_FMU_LIBPYTHON", chosen, sizeof chosen)) {
        if (try_libpython(chosen, NULL, tried, sizeof tried, 0)) return 1;
        snprintf(load_error, sizeof load_error, "SMA_FMU_LIBPYTHON=%.600s cannot be used: %.1200s; set it "
                 "to the libpython3.X.so.1.0 of a Python 3.%d or newer, or unset it", chosen,
                 tried + 2, PYTHON_MIN_MINOR);
        return 0;
    }
    text_append(tried, sizeof tried, "; SMA_FMU_LIBPYTHON: not set");
    if (try_libpython(SMA_FRONT_LIBPYTHON, "the build's ", tried, sizeof tried, 0) ||
        try_libpython(SMA_FRONT_LIBPYTHON_SONAME, "", tried, sizeof tried, 0) ||
        try_any_libpython(tried, sizeof tried))
        return 1;
    snprintf(load_error, sizeof load_error,
             "this FMU runs Python and needs a shared libpython of Python 3.%d or newer, but "
             "none could be loaded. Tried: %s. Set SMA_FMU_LIBPYTHON to the full path of a "
             "libpython3.X.so.1.0 (python3 -c \"import sysconfig,os;print(os.path.join("
             "sysconfig.get_config_var('LIBDIR'),sysconfig.get_config_var('INSTSONAME')))\" "
             "prints it for a Python built with --enable-shared), or LD_PRELOAD it.",
             PYTHON_MIN_MINOR, tried + 2);
    return 0;
}
#endif
