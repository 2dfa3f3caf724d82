/*
 * fmi_host.c - a plain C FMI 2.0 co-simulation host for the tests: no libpython linked,
 * no LD_PRELOAD. It loads DIR/binaries/linux64/<modelIdentifier>.so (built for Windows:
 * DIR/binaries/win64/<modelIdentifier>.dll) like fmusim does and runs FMI calls read from
 * stdin, one command per line, so the tests (and the fuzz suite) can drive any call
 * sequence in a real non-Python process.
 *
 * usage: fmi_host DIR   then commands on stdin; strings are hex-encoded, "-" is NULL:
 *   instantiate S NAME URI GUID LOGGING   URI: ok|one|localhost|plain|empty|null|missing|
 *                                         http|relative|pct or hex text; GUID: ok|wrong|null
 *   free S | setup S T0 STOP(or -) | enter S | exit S | terminate S | reset S
 *   reuse S (put the pointer "free S" freed back into slot S) | bogus S (a pointer that was
 *   never an instance) | forget S (empty slot S without freeing)
 *   setreal S N VR V ... | getreal S N VR ... | setbool S N VR B ... | getbool S N VR ...
 *   setint S N VR I ... | getint S N VR ... | setstring S N VR TEXT ... | getstring S N VR ...
 *   step S T H | getstate S K | setstate S K | freestate S K | serialize S K
 *   deserialize S K BYTES | boolstatus S KIND | realstatus S KIND | debuglog S ON N CAT ...
 *   bench S STEPS H VR_IN VALUE VR_OUT T0 (set + doStep + get from T0; p50/p99/p99.9 in us
 *     from a timed pass, the total [s] of a second, untimed pass of STEPS more steps)
 * Each command prints its log lines ("log STATUS CATEGORY TEXT", text hex-encoded) and then
 * one result line "= STATUS [values]". The logger formats the message like fmusim, the FMI
 * Library and fmpy's log proxy do: as a printf format (which a '%' must not break).
 */
#define _GNU_SOURCE
#include <stdarg.h>

#include "host_platform.h"  /* loading a binary, the platform shim */

#define SLOTS 8
#define MAXN 64
static struct {
    HOST_FMI2_FUNCTIONS(HOST_FMI2_POINTER)  /* the FMU's functions (host_platform.h) */
} F;

static char dir[PATH_SIZE], guid[256], model[256];
static fmi2Component slot[SLOTS], freed[SLOTS];
static char never_an_instance[64];
static void* states[SLOTS][4];

static void print_hex(const char* text, size_t n)
{
    if (!text) { fputs("-", stdout); return; }
    if (n == 0) { fputs("_", stdout); return; }
    for (size_t i = 0; i < n; ++i) printf("%02x", (unsigned char)text[i]);
}

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env; (void)name;
    char text[8192];
    va_list args;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args); /* the message is a printf format (FMI 2.0) */
    va_end(args);
    printf("log %d %s ", status, category && *category ? category : "-");
    print_hex(text, strlen(text));
    putchar('\n');
}

/* hex text -> malloc'd bytes (NUL-terminated); "-" -> NULL, "_" -> "". Two digits at a time
 * through strtol: sscanf per byte measures the rest of the string each call, quadratic in a
 * long string. */
static char* unhex(const char* hex, size_t* length)
{
    if (!strcmp(hex, "-")) { if (length) *length = 0; return NULL; }
    size_t n = strcmp(hex, "_") ? strlen(hex) / 2 : 0;
    char* out = calloc(n + 1, 1);
    for (size_t i = 0; out && i < n; ++i)
        out[i] = (char)strtol((const char[]){hex[2 * i], hex[2 * i + 1], '\0'}, NULL, 16);
    if (length) *length = n;
    return out;
}

static const char* resource_uri(const char* mode)
{
    static char uri[PATH_SIZE + 64];
    char absolute[PATH_SIZE];
#ifdef _WIN32
    const char* root = "/"; /* file:///C:/dir */
#else
    const char* root = "";
#endif
    if (!host_absolute_dir(dir, absolute, sizeof absolute)) return NULL;
    if (!strcmp(mode, "ok")) snprintf(uri, sizeof uri, "file://%s%s/resources", root, absolute);
    else if (!strcmp(mode, "one")) snprintf(uri, sizeof uri, "file:%s%s/resources", root, absolute);
    else if (!strcmp(mode, "localhost")) snprintf(uri, sizeof uri, "file://localhost%s%s/resources", root, absolute);
    else if (!strcmp(mode, "plain")) snprintf(uri, sizeof uri, "%s/resources", absolute);
    else if (!strcmp(mode, "pct")) snprintf(uri, sizeof uri, "file://%s%s/re%%73ources", root, absolute);
    else if (!strcmp(mode, "empty")) uri[0] = '\0';
    else if (!strcmp(mode, "null")) return NULL;
    else if (!strcmp(mode, "missing")) snprintf(uri, sizeof uri, "file://%s%s/nonexistent", root, absolute);
    else if (!strcmp(mode, "http")) snprintf(uri, sizeof uri, "http://example.com%s%s/resources", root, absolute);
    else if (!strcmp(mode, "relative")) snprintf(uri, sizeof uri, "file:resources");
    else { char* text = unhex(mode, NULL); snprintf(uri, sizeof uri, "%s", text ? text : ""); free(text); }
    return uri;
}

static void read_model_description(void)
{
    char why[PATH_SIZE + 64];
    if (host_model_description(dir, guid, model, why, sizeof why)) { fprintf(stderr, "%s\n", why); exit(2); }
}

static void load(void)
{
    char path[PATH_SIZE + 300], why[2 * PATH_SIZE];
    void* library = host_open_library(dir, model, path, sizeof path, why, sizeof why);
    if (!library) { fprintf(stderr, "fmi_host: %s\n", why); exit(3); }
#define SYM(n) if (!(*(void**)&F.n = host_symbol(library, "fmi2" #n))) { fprintf(stderr, "no fmi2" #n "\n"); exit(3); }
    HOST_FMI2_FUNCTIONS(SYM)
#undef SYM
}


static int by_value(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

static void bench(fmi2Component c, long steps, double h, unsigned in, double value, unsigned out, double t)
{
    double* cost = malloc(sizeof(double) * (size_t)steps), result = 0.0;
    int status = 0;
    double start = host_now();
    for (long i = 0; i < steps && status <= 1; ++i) {
        double before = host_now();
        status = F.SetReal(c, &in, 1, &value);
        if (status <= 1) status = F.DoStep(c, t, h, 1);
        if (status <= 1) status = F.GetReal(c, &out, 1, &result);
        cost[i] = host_now() - before;
        t += h;
    }
    double total = host_now() - start;
    /* the mean from a second pass of as many steps without the per-step clock reads (two
     * reads cost 25-90 ns here: as much as a native C FMU step), timed as a whole like the
     * library step it is compared with; the percentiles are the first pass's */
    if (status <= 1) {
        start = host_now();
        for (long i = 0; i < steps && status <= 1; ++i) {
            status = F.SetReal(c, &in, 1, &value);
            if (status <= 1) status = F.DoStep(c, t, h, 1);
            if (status <= 1) status = F.GetReal(c, &out, 1, &result);
            t += h;
        }
        total = host_now() - start;
    }
    qsort(cost, (size_t)steps, sizeof(double), by_value);
    printf("= %d %.17g %.3f %.3f %.3f %.6f\n", status, result, 1e6 * cost[steps / 2],
           1e6 * cost[(long)(steps * 0.99)], 1e6 * cost[(long)(steps * 0.999)], total);
    free(cost);
}

int main(int argc, char** argv)
{
    if (argc != 2) { fprintf(stderr, "usage: fmi_host DIR < commands\n"); return 2; }
    snprintf(dir, sizeof dir, "%s", argv[1]);
    read_model_description();
    load();
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    static char line[1 << 20];
    while (fgets(line, sizeof line, stdin)) {
        char* word[4 * MAXN + 8];
        int n = 0;
        for (char* p = strtok(line, " \n"); p && n < 4 * MAXN + 8; p = strtok(NULL, " \n")) word[n++] = p;
        if (n == 0) continue;
        const char* command = word[0];
        if (!strcmp(command, "end")) break;
        int s = n > 1 ? atoi(word[1]) % SLOTS : 0;
        fmi2Component c = slot[s];
        unsigned vr[MAXN];
        int count = n > 2 ? atoi(word[2]) : 0;
        if (count < 0 || count > MAXN) count = 0;
        int status = -1;
        if (!strcmp(command, "instantiate") && n == 6) {
            char* name = unhex(word[2], NULL);
            const char* id = !strcmp(word[4], "ok") ? guid : !strcmp(word[4], "wrong") ? "{00000000-0}" : NULL;
            slot[s] = F.Instantiate(name, fmi2CoSimulation, id, resource_uri(word[3]), &callbacks, 0, atoi(word[5]));
            free(name);
            printf("= %d\n", slot[s] ? 0 : 3);
            fflush(stdout);
            continue;
        }
        if (!strcmp(command, "reuse") || !strcmp(command, "bogus") || !strcmp(command, "forget")) {
            slot[s] = !strcmp(command, "reuse") ? freed[s]
                      : !strcmp(command, "bogus") ? (fmi2Component)never_an_instance : NULL;
            printf("= 0\n");
            fflush(stdout);
            continue;
        }
        if (!c) { printf("= -2\n"); fflush(stdout); continue; } /* no instance in this slot */
        if (!strcmp(command, "free")) {
            F.FreeInstance(c);
            freed[s] = c;
            slot[s] = NULL;
            memset(states[s], 0, sizeof states[s]);
            status = 0;
        }
        else if (!strcmp(command, "setup") && n == 4)
            status = F.SetupExperiment(c, 0, 0.0, strtod(word[2], NULL), strcmp(word[3], "-") != 0,
                                       strtod(word[3], NULL));
        else if (!strcmp(command, "enter")) status = F.EnterInitializationMode(c);
        else if (!strcmp(command, "exit")) status = F.ExitInitializationMode(c);
        else if (!strcmp(command, "terminate")) status = F.Terminate(c);
        else if (!strcmp(command, "reset")) status = F.Reset(c);
        else if (!strcmp(command, "step") && n == 4) status = F.DoStep(c, strtod(word[2], NULL), strtod(word[3], NULL), 1);
        else if (!strncmp(command, "set", 3) && n >= 3 + 2 * count && strcmp(command, "setstate") && strcmp(command, "setup")) {
            double reals[MAXN];
            int ints[MAXN];
            char* texts[MAXN];
            for (int i = 0; i < count; ++i) {
                vr[i] = (unsigned)strtoul(word[3 + 2 * i], NULL, 10);
                const char* v = word[4 + 2 * i];
                reals[i] = strtod(v, NULL);
                ints[i] = (int)strtol(v, NULL, 10);
                texts[i] = !strcmp(command, "setstring") ? unhex(v, NULL) : NULL;
            }
            if (!strcmp(command, "setreal")) status = F.SetReal(c, vr, (size_t)count, reals);
            else if (!strcmp(command, "setint")) status = F.SetInteger(c, vr, (size_t)count, ints);
            else if (!strcmp(command, "setbool")) status = F.SetBoolean(c, vr, (size_t)count, ints);
            else if (!strcmp(command, "setstring")) status = F.SetString(c, vr, (size_t)count, (const char* const*)texts);
            for (int i = 0; i < count; ++i) free(texts[i]);
        } else if (!strncmp(command, "get", 3) && strcmp(command, "getstate") && n >= 3 + count) {
            double reals[MAXN];
            int ints[MAXN];
            const char* texts[MAXN] = {0};
            for (int i = 0; i < count; ++i) vr[i] = (unsigned)strtoul(word[3 + i], NULL, 10);
            if (!strcmp(command, "getreal")) status = F.GetReal(c, vr, (size_t)count, reals);
            else if (!strcmp(command, "getint")) status = F.GetInteger(c, vr, (size_t)count, ints);
            else if (!strcmp(command, "getbool")) status = F.GetBoolean(c, vr, (size_t)count, ints);
            else if (!strcmp(command, "getstring")) status = F.GetString(c, vr, (size_t)count, texts);
            printf("= %d", status);
            for (int i = 0; i < count && status >= 0; ++i) {
                if (!strcmp(command, "getreal")) printf(" %.17g", reals[i]);
                else if (!strcmp(command, "getstring")) { putchar(' '); print_hex(texts[i], texts[i] ? strlen(texts[i]) : 0); }
                else printf(" %d", ints[i]);
            }
            putchar('\n');
            fflush(stdout);
            continue;
        } else if (n >= 3 && strstr(command, "state")) {
            int k = atoi(word[2]) & 3;
            if (!strcmp(command, "getstate")) status = F.GetFMUstate(c, &states[s][k]);
            else if (!strcmp(command, "setstate")) status = F.SetFMUstate(c, states[s][k]);
            else if (!strcmp(command, "freestate")) status = F.FreeFMUstate(c, &states[s][k]);
        } else if (!strcmp(command, "serialize") && n == 3) {
            int k = atoi(word[2]) & 3;
            size_t size = 0;
            status = F.SerializedFMUstateSize(c, states[s][k], &size);
            char* bytes = status <= 1 ? malloc(size + 1) : NULL;
            if (bytes) status = F.SerializeFMUstate(c, states[s][k], bytes, size);
            printf("= %d ", status);
            print_hex(bytes, status <= 1 ? size : 0);
            putchar('\n');
            free(bytes);
            fflush(stdout);
            continue;
        } else if (!strcmp(command, "deserialize") && n == 4) {
            size_t size = 0;
            char* bytes = unhex(word[3], &size);
            status = F.DeSerializeFMUstate(c, bytes ? bytes : "", size, &states[s][atoi(word[2]) & 3]);
            free(bytes);
        } else if (!strcmp(command, "boolstatus") && n == 3) {
            int value = -1;
            status = F.GetBooleanStatus(c, atoi(word[2]), &value);
            printf("= %d %d\n", status, value);
            fflush(stdout);
            continue;
        } else if (!strcmp(command, "realstatus") && n == 3) {
            double value = -1;
            status = F.GetRealStatus(c, atoi(word[2]), &value);
            printf("= %d %.17g\n", status, value);
            fflush(stdout);
            continue;
        } else if (!strcmp(command, "debuglog") && n >= 4) {
            int k = atoi(word[3]) > 0 && atoi(word[3]) <= MAXN ? atoi(word[3]) : 0;
            char* categories[MAXN];
            for (int i = 0; i < k && 4 + i < n; ++i) categories[i] = unhex(word[4 + i], NULL);
            status = F.SetDebugLogging(c, atoi(word[2]), (size_t)k, (const char* const*)categories);
            for (int i = 0; i < k && 4 + i < n; ++i) free(categories[i]);
        } else if (!strcmp(command, "bench") && n == 8 && atol(word[2]) > 0) {
            bench(c, atol(word[2]), strtod(word[3], NULL), (unsigned)atoi(word[4]), strtod(word[5], NULL),
                  (unsigned)atoi(word[6]), strtod(word[7], NULL));
            fflush(stdout);
            continue;
        }
        printf("= %d\n", status);
        fflush(stdout);
    }
    for (int s = 0; s < SLOTS; ++s)
        if (slot[s]) F.FreeInstance(slot[s]);
    printf("bye\n");
    return 0;
}
