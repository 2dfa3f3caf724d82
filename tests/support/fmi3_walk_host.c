/* A small FMI 3.0 co-simulation host for the tests (tests/hosts/test_fmi3_windows.py): loads
 * DIR/binaries/<x86_64-linux|x86_64-windows>/<MODEL><.so|.dll>, instantiates it with TOKEN,
 * sets INPUT (a Float64 value reference, or -1 for none) to a fixed deterministic walk, steps
 * STEPS steps of H s and prints after each step the Float64 outputs OUT... with %.17g.
 * Every log message goes to stderr as "log <status> <message>". Exit 0: every call OK.
 * Usage: fmi3_walk_host DIR MODEL TOKEN STEPS H INPUT OUT... */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3FunctionTypes.h"

#ifdef _WIN32
#include <windows.h>
#define PLATFORM "x86_64-windows"
#define SUFFIX ".dll"
#define SEP "\\"
static void *open_library(const char *path) { return (void *)LoadLibraryA(path); }
static void *lookup(void *library, const char *name)
{
    return (void *)(size_t)GetProcAddress((HMODULE)library, name);
}
#else
#include <dlfcn.h>
#define PLATFORM "x86_64-linux"
#define SUFFIX ".so"
#define SEP "/"
static void *open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *lookup(void *library, const char *name) { return dlsym(library, name); }
#endif

static void logger(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category,
                   fmi3String message)
{
    (void)environment;
    (void)category;
    fprintf(stderr, "log %d %s\n", (int)status, message);
}

/* dlsym's object pointer into a function pointer, without a cast ISO C forbids */
#define LOAD(T, name)                                                                          \
    T *name;                                                                                   \
    {                                                                                          \
        void *found = lookup(library, #name);                                                  \
        if (!found) { fprintf(stderr, "no %s\n", #name); return 2; }                          \
        memcpy(&name, &found, sizeof found);                                                   \
    }

int main(int argc, char **argv)
{
    char path[4096], resources[4096];
    void *library;
    fmi3Instance instance;
    int steps, k, i, count, failed = 0;
    double h, t = 0.0;
    long input;
    fmi3ValueReference outputs[32];
    if (argc < 8) { fprintf(stderr, "usage: DIR MODEL TOKEN STEPS H INPUT OUT...\n"); return 2; }
    steps = atoi(argv[4]);
    h = atof(argv[5]);
    input = atol(argv[6]);
    count = argc - 7 > 32 ? 32 : argc - 7;
    for (i = 0; i < count; ++i) outputs[i] = (fmi3ValueReference)atol(argv[7 + i]);
    snprintf(path, sizeof path, "%s" SEP "binaries" SEP PLATFORM SEP "%s" SUFFIX, argv[1], argv[2]);
    snprintf(resources, sizeof resources, "%s" SEP "resources" SEP, argv[1]);
    library = open_library(path);
    if (!library) { fprintf(stderr, "cannot load %s\n", path); return 2; }
    {
        LOAD(fmi3InstantiateCoSimulationTYPE, fmi3InstantiateCoSimulation)
        LOAD(fmi3EnterInitializationModeTYPE, fmi3EnterInitializationMode)
        LOAD(fmi3ExitInitializationModeTYPE, fmi3ExitInitializationMode)
        LOAD(fmi3SetFloat64TYPE, fmi3SetFloat64)
        LOAD(fmi3GetFloat64TYPE, fmi3GetFloat64)
        LOAD(fmi3DoStepTYPE, fmi3DoStep)
        LOAD(fmi3TerminateTYPE, fmi3Terminate)
        LOAD(fmi3FreeInstanceTYPE, fmi3FreeInstance)
        instance = fmi3InstantiateCoSimulation("walk", argv[3], resources, fmi3False, fmi3False,
                                               fmi3False, fmi3False, NULL, 0, NULL, logger, NULL);
        if (!instance) { fprintf(stderr, "instantiation failed\n"); return 1; }
        failed |= fmi3EnterInitializationMode(instance, fmi3False, 0.0, 0.0, fmi3False, 0.0) != fmi3OK;
        failed |= fmi3ExitInitializationMode(instance) != fmi3OK;
        for (k = 0; k < steps && !failed; ++k) {
            fmi3Boolean event, terminate, early;
            fmi3Float64 last, values[32];
            if (input >= 0) {
                fmi3ValueReference vr = (fmi3ValueReference)input;
                fmi3Float64 u = 1.0 + 0.9 * sin(k / 97.0) * cos(k / 613.0);
                failed |= fmi3SetFloat64(instance, &vr, 1, &u, 1) != fmi3OK;
            }
            failed |= fmi3DoStep(instance, t, h, fmi3True, &event, &terminate, &early, &last) != fmi3OK;
            t = last;
            failed |= fmi3GetFloat64(instance, outputs, (size_t)count, values, (size_t)count) != fmi3OK;
            for (i = 0; i < count; ++i) printf(i ? " %.17g" : "%.17g", values[i]);
            printf("\n");
        }
        failed |= fmi3Terminate(instance) != fmi3OK;
        fmi3FreeInstance(instance);
    }
    return failed ? 1 : 0;
}
