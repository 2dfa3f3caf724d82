/* Loads and unloads a native FMU binary many times, with instances made and freed in each
 * cycle, and prints the process's resident memory (VmRSS, kB) after the warm-up cycles and
 * at the end (tests/native/test_native_unload.py). Usage:
 *   native_unload_host BINARY GUID RESOURCE_URI WARMUP CYCLES INSTANCES */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *(*Instantiate)(const char *, int, const char *, const char *, const void *, int, int);
typedef void (*FreeInstance)(void *);

static long rss_kb(void)
{
    char line[256];
    long kb = -1;
    FILE *status = fopen("/proc/self/status", "r");
    if (!status) return -1;
    while (fgets(line, sizeof line, status))
        if (strncmp(line, "VmRSS:", 6) == 0) kb = strtol(line + 6, NULL, 10);
    fclose(status);
    return kb;
}

/* One cycle: load, make and free `instances` instances, unload; 0 on success. */
static int cycle(const char *binary, const char *guid, const char *uri, long instances)
{
    void *library = dlopen(binary, RTLD_NOW | RTLD_LOCAL);
    Instantiate instantiate;
    FreeInstance free_instance;
    long i;
    if (!library) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 1; }
    *(void **)&instantiate = dlsym(library, "fmi2Instantiate");
    *(void **)&free_instance = dlsym(library, "fmi2FreeInstance");
    if (!instantiate || !free_instance) { fprintf(stderr, "dlsym failed\n"); return 1; }
    for (i = 0; i < instances; ++i) {
        void *component = instantiate("unload", 1, guid, uri, NULL, 0, 0);
        if (!component) { fprintf(stderr, "fmi2Instantiate failed\n"); return 1; }
        free_instance(component);
    }
    return dlclose(library) != 0;
}

int main(int argc, char **argv)
{
    long warmup, cycles, instances, k;
    if (argc != 7) { fprintf(stderr, "usage: %s BINARY GUID URI WARMUP CYCLES INSTANCES\n", argv[0]); return 2; }
    warmup = atol(argv[4]);
    cycles = atol(argv[5]);
    instances = atol(argv[6]);
    for (k = 0; k < warmup; ++k)
        if (cycle(argv[1], argv[2], argv[3], instances)) return 1;
    printf("%ld\n", rss_kb());
    for (k = 0; k < cycles; ++k)
        if (cycle(argv[1], argv[2], argv[3], instances)) return 1;
    printf("%ld\n", rss_kb());
    return 0;
}
