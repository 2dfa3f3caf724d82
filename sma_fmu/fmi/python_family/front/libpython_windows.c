/*
 * libpython_windows.c - finding the Python the backend runs in, on Windows.
 *
 * pythonfmu's DLL imports the stable-ABI python3.dll, which forwards to the python3X.dll
 * beside it. Windows has no global symbol scope: the loader binds that import to a
 * python3.dll the process has already loaded, else searches for one. The front therefore
 * chooses a Python first, loads its python3X.dll and python3.dll by full path, and only
 * then pythonfmu's DLL. It tries in turn
 *   1. a python3X.dll the process has loaded already (a Python host): that one or nothing;
 *   2. %SMA_FMU_LIBPYTHON% (a python3X.dll; nothing else when it is set);
 *   3. Python 3.PYTHON_MAX_MINOR down to 3.PYTHON_MIN_MINOR, newest first, found the way
 *      Windows Pythons are found (PEP 514): the registry keys
 *      HKCU and HKLM\Software\Python\PythonCore\3.X\InstallPath, then python3X.dll on the
 *      DLL search path (PATH), then the python.org installer's folders
 *      %LOCALAPPDATA%\Programs\Python\Python3X and %ProgramFiles%\Python3X.
 * Every Python, the process's own too, must be 3.PYTHON_MIN_MINOR or newer.
 */
#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"

static HMODULE python; /* the python3X.dll in use */

void* python_symbol(const char* name) { return python ? library_symbol(python, name) : NULL; }

static int module_file(HMODULE module, char* path, size_t size)
{
    wchar_t name[PATH_SIZE];
    DWORD n = GetModuleFileNameW(module, name, PATH_SIZE);
    return n > 0 && n < PATH_SIZE &&
           WideCharToMultiByte(CP_UTF8, 0, name, -1, path, (int)size, NULL, NULL) > 0;
}

int python_library_file(char* path, size_t size) { return python && module_file(python, path, size); }

/* Use `module` (a loaded python3X.dll) if its version is supported; else 0, reason in why. */
static int accept(HMODULE module, const char* how, char* why, size_t size)
{
    char version[32], file[PATH_SIZE] = "?";
    python_version(library_symbol(module, "Py_GetVersion"), version);
    module_file(module, file, sizeof file);
    if (!library_symbol(module, "Py_IsInitialized")) {
        snprintf(why, size, "%s is not a Python DLL (no Py_IsInitialized)", file);
        return 0;
    }
    if (!python_version_supported(version, why, size)) return 0;
    python = module;
    snprintf(load_info, sizeof load_info, "%s %s (Python %s)", how, file, version);
    return 1;
}

/* Load the python3X.dll `path`, and the python3.dll beside it, which pythonfmu imports. */
static int try_dll(const char* path, const char* label, char* tried, size_t size, int quiet)
{
    char reason[512];
    Library module = library_open(path, 1, 0, reason, sizeof reason);
    if (!module) {
        int missing = strncmp(reason, "error 126", 9) == 0 || strncmp(reason, "error 2:", 8) == 0;
        if (!(quiet && missing)) text_append(tried, size, "; %s%s: %s", label, path, reason);
        return 0;
    }
    char why[512];
    if (!accept((HMODULE)module, "loaded", why, sizeof why)) {
        text_append(tried, size, "; %s%s: %s", label, path, why);
        library_close(module);
        return 0;
    }
    library_open(path, 1, 1, NULL, 0); /* pinned: Python is never unloaded */
    char stable[PATH_SIZE];
    if (module_file((HMODULE)module, stable, sizeof stable)) {
        char* slash = strrchr(stable, '\\');
        if (slash) {
            snprintf(slash + 1, sizeof stable - (size_t)(slash + 1 - stable), "python3.dll");
            library_open(stable, 1, 1, NULL, 0); /* if absent, the loader searches for one */
        }
    }
    return 1;
}

/* InstallPath of PythonCore\3.<minor> under `root`, into folder. */
static int registry_folder(HKEY root, int minor, char* folder, size_t size)
{
    wchar_t key[128], value[PATH_SIZE];
    DWORD bytes = sizeof value;
    _snwprintf(key, 128, L"Software\\Python\\PythonCore\\3.%d\\InstallPath", minor);
    key[127] = L'\0';
    if (RegGetValueW(root, key, NULL, RRF_RT_REG_SZ, NULL, value, &bytes) != ERROR_SUCCESS)
        return 0;
    return WideCharToMultiByte(CP_UTF8, 0, value, -1, folder, (int)size, NULL, NULL) > 0;
}

/* python3<minor>.dll in `folder`; a registered folder without it is reported. */
static int try_folder(const char* folder, int minor, const char* label, char* tried, size_t size,
                      int registered)
{
    char path[PATH_SIZE];
    size_t n = strlen(folder);
    const char* sep = n && (folder[n - 1] == '\\' || folder[n - 1] == '/') ? "" : "\\";
    snprintf(path, sizeof path, "%s%spython3%d.dll", folder, sep, minor);
    if (!is_readable_file(path)) {
        if (registered) text_append(tried, size, "; %s%s: not found", label, path);
        return 0;
    }
    return try_dll(path, label, tried, size, 0);
}

int load_libpython(void)
{
    char why[512];
    for (int minor = PYTHON_MAX_MINOR; minor >= 0; --minor) { /* 1: a Python host's own */
        wchar_t name[32];
        _snwprintf(name, 32, L"python3%d.dll", minor);
        name[31] = L'\0';
        HMODULE loaded = GetModuleHandleW(name);
        if (!loaded) continue;
        if (accept(loaded, "the process already has Python:", why, sizeof why)) return 1;
        snprintf(load_error, sizeof load_error, "the Python in this process: %s", why);
        return 0;
    }
    if (GetModuleHandleW(L"python27.dll")) {
        snprintf(load_error, sizeof load_error, "the Python in this process: Python 2.7 is not "
                 "supported: this FMU needs Python 3.%d or newer", PYTHON_MIN_MINOR);
        return 0;
    }
    char tried[sizeof load_error - 512] = "";
    char chosen[PATH_SIZE];
    if (environment("SMA_FMU_LIBPYTHON", chosen, sizeof chosen)) { /* 2 */
        if (try_dll(chosen, "", tried, sizeof tried, 0)) return 1;
        snprintf(load_error, sizeof load_error, "SMA_FMU_LIBPYTHON=%.600s cannot be used: %.1200s; set it "
                 "to the python3X.dll of a Python 3.%d or newer, or unset it", chosen, tried + 2,
                 PYTHON_MIN_MINOR);
        return 0;
    }
    text_append(tried, sizeof tried, "; SMA_FMU_LIBPYTHON: not set");
    char local[PATH_SIZE] = "", programs[PATH_SIZE] = "";
    environment("LOCALAPPDATA", local, sizeof local);
    environment("ProgramFiles", programs, sizeof programs);
    for (int minor = PYTHON_MAX_MINOR; minor >= PYTHON_MIN_MINOR; --minor) { /* 3 */
        char folder[PATH_SIZE], name[32];
        if (registry_folder(HKEY_CURRENT_USER, minor, folder, sizeof folder) &&
            try_folder(folder, minor, "HKCU registry: ", tried, sizeof tried, 1))
            return 1;
        if (registry_folder(HKEY_LOCAL_MACHINE, minor, folder, sizeof folder) &&
            try_folder(folder, minor, "HKLM registry: ", tried, sizeof tried, 1))
            return 1;
        snprintf(name, sizeof name, "python3%d.dll", minor);
        if (try_dll(name, "", tried, sizeof tried, 1)) return 1;
        if (*local) {
            snprintf(folder, sizeof folder, "%s\\Programs\\Python\\Python3%d", local, minor);
            if (try_folder(folder, minor, "", tried, sizeof tried, 0)) return 1;
        }
        if (*programs) {
            snprintf(folder, sizeof folder, "%s\\Python3%d", programs, minor);
            if (try_folder(folder, minor, "", tried, sizeof tried, 0)) return 1;
        }
    }
    text_append(tried, sizeof tried, "; Python 3.%d to 3.%d in the registry (HKCU and HKLM "
           "Software\\Python\\PythonCore\\3.X\\InstallPath), python3X.dll on the DLL search "
           "path (PATH) and in %s\\Programs\\Python\\Python3X and %s\\Python3X: none",
           PYTHON_MAX_MINOR, PYTHON_MIN_MINOR, *local ? local : "%LOCALAPPDATA%",
           *programs ? programs : "%ProgramFiles%");
    snprintf(load_error, sizeof load_error,
             "this FMU runs Python and needs a Python 3.%d or newer for Windows (64-bit, from "
             "python.org or the Microsoft Store), but none could be loaded. Tried: %s. Install "
             "one, or set SMA_FMU_LIBPYTHON to the full path of its python3X.dll.",
             PYTHON_MIN_MINOR, tried + 2);
    return 0;
}
#endif
