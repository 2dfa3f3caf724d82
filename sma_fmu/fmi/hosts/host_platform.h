/*
 * host_platform.h - what every sma-fmu C host needs to load an FMI 2.0 binary, for Linux
 * (dlopen) and Windows (LoadLibrary, the mingw-w64 build run under wine): the platform's
 * folder and suffix, the FMI 2.0 types (the standard's fmi2FunctionTypes.h, in
 * fmi/c_common/include/), reading the GUID and model identifier, opening
 * DIR/binaries/<platform>/<model><suffix>, looking up a function, absolute paths and a
 * monotonic clock. Header-only (static functions): each host is one translation unit, which
 * `compile_host` (hosts/__init__.py) compiles with this folder and the standard's headers on
 * the include path.
 */
#ifndef SMA_FMU_HOST_PLATFORM_H
#define SMA_FMU_HOST_PLATFORM_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#define PLATFORM "win64"
#define SUFFIX ".dll"
#else
#include <dlfcn.h>
#ifndef PLATFORM  /* a cross-built host names its folder: -DPLATFORM='"aarch64-linux"' */
#define PLATFORM "linux64"
#endif
#define SUFFIX ".so"
#endif

#include "fmi2FunctionTypes.h"

#define PATH_SIZE 4096

/* The FMI 2.0 functions the hosts call, named once: HOST_FMI2_FUNCTIONS(X) applies X to each
 * name, HOST_FMI2_POINTER declares its pointer, typed fmi2<name>TYPE by the standard. */
#define HOST_FMI2_FUNCTIONS(X)                                                                  \
    X(Instantiate) X(FreeInstance) X(SetupExperiment) X(EnterInitializationMode)                \
    X(ExitInitializationMode) X(Terminate) X(Reset) X(SetReal) X(GetReal) X(SetInteger)         \
    X(GetInteger) X(SetBoolean) X(GetBoolean) X(SetString) X(GetString) X(DoStep)               \
    X(GetFMUstate) X(SetFMUstate) X(FreeFMUstate) X(SerializedFMUstateSize)                     \
    X(SerializeFMUstate) X(DeSerializeFMUstate) X(GetBooleanStatus) X(GetRealStatus)            \
    X(SetDebugLogging)
#define HOST_FMI2_POINTER(name) fmi2##name##TYPE* name;

/* Read the GUID and modelIdentifier of DIR/modelDescription.xml (each at most 255 bytes);
 * 0 on success, else 1 with `why` saying what failed. */
static int host_model_description(const char* dir, char* guid, char* model, char* why, size_t size)
{
    char path[PATH_SIZE + 32];
    snprintf(path, sizeof path, "%s/modelDescription.xml", dir);
    FILE* file = fopen(path, "r");
    if (!file) { snprintf(why, size, "cannot open %s", path); return 1; }
    static char xml[1 << 18];
    xml[fread(xml, 1, sizeof xml - 1, file)] = '\0';
    fclose(file);
    char* g = strstr(xml, " guid=\"");
    char* m = strstr(xml, "modelIdentifier=\"");
    if (!g || !m) { snprintf(why, size, "no guid or modelIdentifier in %s", path); return 1; }
    sscanf(g + 7, "%255[^\"]", guid);
    sscanf(m + 17, "%255[^\"]", model);
    return 0;
}

/* Open DIR/binaries/<platform>/<model><suffix> (its path written to `path`); the library,
 * or NULL with `why` saying what failed. */
static void* host_open_library(const char* dir, const char* model, char* path, size_t path_size,
                               char* why, size_t size)
{
    snprintf(path, path_size, "%s/binaries/" PLATFORM "/%s" SUFFIX, dir, model);
#ifdef _WIN32
    for (char* p = path; *p; ++p)
        if (*p == '/') *p = '\\';
    HMODULE library = LoadLibraryExA(path, NULL, LOAD_WITH_ALTERED_SEARCH_PATH);
    if (!library) snprintf(why, size, "LoadLibrary %s: error %lu", path, GetLastError());
    return (void*)library;
#else
    void* library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!library) snprintf(why, size, "dlopen: %s", dlerror());
    return library;
#endif
}

/* The function `name` of an open library, or NULL. */
static void* host_symbol(void* library, const char* name)
{
#ifdef _WIN32
    FARPROC address = GetProcAddress((HMODULE)library, name);
    void* pointer;
    memcpy(&pointer, &address, sizeof pointer);
    return pointer;
#else
    return dlsym(library, name);
#endif
}

/* The absolute path of `dir`, '/'-separated ("C:/dir" on Windows); 1 on success. */
static int host_absolute_dir(const char* dir, char* absolute, size_t size)
{
#ifdef _WIN32
    if (!_fullpath(absolute, dir, size)) return 0;
    for (char* p = absolute; *p; ++p)
        if (*p == '\\') *p = '/';
    return 1;
#else
    (void)size;
    return realpath(dir, absolute) != NULL;
#endif
}

/* Seconds on a monotonic clock. */
static double host_now(void)
{
#ifdef _WIN32
    LARGE_INTEGER count, frequency;
    QueryPerformanceCounter(&count);
    QueryPerformanceFrequency(&frequency);
    return (double)count.QuadPart / (double)frequency.QuadPart;
#else
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
#endif
}

#endif
