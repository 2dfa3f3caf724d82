/*
 * platform_windows.c - platform.h for Windows: LoadLibraryExW, GetModuleHandleExW,
 * LockFileEx, SRW locks, fiber-local storage (its callback runs when a thread ends).
 * UTF-8 paths and variables are converted to and from UTF-16.
 */
#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "platform.h"

/* UTF-8 -> malloc'd UTF-16, or NULL. */
static wchar_t* wide(const char* text)
{
    int n = MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, text, -1, NULL, 0);
    if (n <= 0) return NULL;
    wchar_t* out = (wchar_t*)malloc(sizeof(wchar_t) * (size_t)n);
    if (out && MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, text, -1, out, n) <= 0) {
        free(out);
        return NULL;
    }
    return out;
}

static int narrow(const wchar_t* text, char* out, size_t size)
{
    int n = WideCharToMultiByte(CP_UTF8, 0, text, -1, out, (int)size, NULL, NULL);
    return n > 0;
}

static void system_message(DWORD code, char* err, size_t errlen)
{
    wchar_t text[512];
    char utf8[1024];
    if (FormatMessageW(FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, NULL, code, 0,
                       text, sizeof text / sizeof text[0], NULL) && narrow(text, utf8, sizeof utf8)) {
        utf8[strcspn(utf8, "\r\n")] = '\0';
        snprintf(err, errlen, "error %lu: %s", (unsigned long)code, utf8);
    } else {
        snprintf(err, errlen, "error %lu", (unsigned long)code);
    }
}

Library library_open(const char* path, int global, int pinned, char* err, size_t errlen)
{
    (void)global; /* Windows has no global symbol scope: imports bind by DLL name */
    wchar_t* name = wide(path);
    if (!name) {
        if (err) snprintf(err, errlen, "the path is not UTF-8");
        return NULL;
    }
    /* a full path: its own folder is searched first for the DLLs it imports (which needs
     * backslashes) */
    DWORD flags = 0;
    for (wchar_t* p = name; *p; ++p) {
        if (*p == L'/') *p = L'\\';
        if (*p == L'\\') flags = LOAD_WITH_ALTERED_SEARCH_PATH;
    }
    HMODULE module = LoadLibraryExW(name, NULL, flags);
    DWORD code = GetLastError();
    free(name);
    if (!module) {
        if (err) system_message(code, err, errlen);
        return NULL;
    }
    if (pinned) {
        HMODULE same;
        GetModuleHandleExW(GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_PIN,
                           (LPCWSTR)(void*)module, &same);
    }
    return (Library)module;
}

void* library_symbol(Library library, const char* name)
{
    FARPROC address = GetProcAddress((HMODULE)library, name);
    void* pointer;
    memcpy(&pointer, &address, sizeof pointer);
    return pointer;
}

void library_close(Library library)
{
    if (library) FreeLibrary((HMODULE)library);
}

static HMODULE self_module(void)
{
    HMODULE module = NULL;
    GetModuleHandleExW(GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS |
                       GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT, (LPCWSTR)(void*)&self_module,
                       &module);
    return module;
}

int self_path(char* path, size_t size)
{
    wchar_t name[PATH_SIZE];
    HMODULE module = self_module();
    DWORD n = module ? GetModuleFileNameW(module, name, PATH_SIZE) : 0;
    if (n == 0 || n >= PATH_SIZE || !narrow(name, path, size)) return 0;
    for (char* p = path; *p; ++p)
        if (*p == '\\') *p = '/';
    return 1;
}

void pin_self(void)
{
    HMODULE module;
    GetModuleHandleExW(GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_PIN,
                       (LPCWSTR)(void*)&pin_self, &module);
}

FILE* file_open(const char* path, const char* mode)
{
    wchar_t* name = wide(path);
    wchar_t* how = wide(mode);
    FILE* file = name && how ? _wfopen(name, how) : NULL;
    free(name);
    free(how);
    return file;
}

static DWORD attributes(const char* path)
{
    wchar_t* name = wide(path);
    DWORD found = name ? GetFileAttributesW(name) : INVALID_FILE_ATTRIBUTES;
    free(name);
    return found;
}

int is_directory(const char* path)
{
    DWORD found = attributes(path);
    return found != INVALID_FILE_ATTRIBUTES && (found & FILE_ATTRIBUTE_DIRECTORY);
}

int is_readable_file(const char* path)
{
    DWORD found = attributes(path);
    return found != INVALID_FILE_ATTRIBUTES && !(found & FILE_ATTRIBUTE_DIRECTORY);
}

void* lock_file(const char* path)
{
    wchar_t* name = wide(path);
    if (!name) return NULL;
    HANDLE file = CreateFileW(name, GENERIC_READ, FILE_SHARE_READ | FILE_SHARE_WRITE |
                              FILE_SHARE_DELETE, NULL, OPEN_EXISTING, FILE_ATTRIBUTE_NORMAL, NULL);
    free(name);
    if (file == INVALID_HANDLE_VALUE) return NULL;
    OVERLAPPED whole = {0};
    if (!LockFileEx(file, LOCKFILE_EXCLUSIVE_LOCK, 0, MAXDWORD, MAXDWORD, &whole)) {
        CloseHandle(file);
        return NULL;
    }
    return (void*)file;
}

void unlock_file(void* lock)
{
    if (!lock) return;
    OVERLAPPED whole = {0};
    UnlockFileEx((HANDLE)lock, 0, MAXDWORD, MAXDWORD, &whole);
    CloseHandle((HANDLE)lock);
}

void mutex_lock(Mutex* mutex) { AcquireSRWLockExclusive((PSRWLOCK)mutex); }
void mutex_unlock(Mutex* mutex) { ReleaseSRWLockExclusive((PSRWLOCK)mutex); }

static DWORD slot = FLS_OUT_OF_INDEXES;
static void (*slot_destructor)(void*);

static void WINAPI slot_callback(void* value)
{
    if (value && slot_destructor) slot_destructor(value);
}

int thread_slot_create(void (*at_thread_exit)(void*))
{
    slot_destructor = at_thread_exit;
    slot = FlsAlloc(slot_callback);
    return slot != FLS_OUT_OF_INDEXES;
}

void* thread_slot_get(void) { return slot == FLS_OUT_OF_INDEXES ? NULL : FlsGetValue(slot); }

void thread_slot_set(void* value)
{
    if (slot != FLS_OUT_OF_INDEXES) FlsSetValue(slot, value);
}

int environment(const char* name, char* value, size_t size)
{
    wchar_t* key = wide(name);
    wchar_t text[PATH_SIZE];
    DWORD n = key ? GetEnvironmentVariableW(key, text, PATH_SIZE) : 0;
    free(key);
    return n > 0 && n < PATH_SIZE && narrow(text, value, size);
}
#endif
