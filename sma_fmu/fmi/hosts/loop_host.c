/*
 * loop_host.c - a plain C host that runs a system of FMI 2.0 co-simulation FMUs as a
 * sequential (Gauss-Seidel) loop, the way an embedded or HIL master does: no libpython, no
 * FMI library, one process. It loads DIR/binaries/linux64/<id>.so (built for Windows with
 * mingw-w64: DIR/binaries/win64/<id>.dll, run under wine), so the same source runs the
 * linux64 and the win64 binaries of the same FMUs and their outputs can be compared.
 *
 * usage: loop_host < SYSTEM   where SYSTEM has one item a line (strings hex-encoded):
 *   fmu NAME DIR                   a component (unpacked FMU folder); the order of these
 *                                  lines is the data-flow order of initialization
 *   real|integer|boolean NAME VR VALUE   a start value, set in Initialization Mode
 *   string NAME VR HEX             a String start value
 *   connect SRC VR DST VR          the Real output SRC.VR feeds the Real input DST.VR
 *   order NAME ...                 the step order (Gauss-Seidel: each component takes the
 *                                  outputs of those before it in this step)
 *   record real|boolean NAME VR    a recorded output (one column)
 *   run STEP_S STEPS [timing|binary ROWS]   initialize, then STEPS steps of STEP_S at
 *                                  t_k = k STEP_S
 * Initialization: in the order of the fmu lines, each component gets its start values and
 * the current outputs of its sources, then leaves Initialization Mode.
 * Output: "row V..." (%.17g; Booleans 0/1) after initialization and after every step; with
 * "timing", only the last row and first "timing P50_US P99_US P999_US MAX_US TOTAL_S" of the
 * wall time of each step (all components set, stepped and read). Every FMU log message is a
 * line "log STATUS NAME CATEGORY TEXT" (TEXT hex, formatted as printf like fmusim does).
 * Exit status 0, 1 when an FMI call fails (stderr names it), 2 on a bad system.
 * "binary ROWS" (the C master of `sma-fmu run --master c`): stdout is a stream of frames,
 * each a 4-byte tag and a 4-byte little-endian length of the payload that follows:
 *   ROWS  rows of the recorded columns, raw doubles (Booleans 0.0/1.0): ROWS + 1 in the
 *         first frame, ROWS in the others (the last one fewer), so that each frame
 *         completes ROWS rows of the loop (row k holds the outputs after step k);
 *   LOG_  "STATUS NAME CATEGORY\tTEXT" of an FMU log message;
 *   FAIL  "NAME.CALL returned STATUS at t = T s" of a failed call (status > fmi2Warning),
 *         after the rows up to that step: the host then exits with status 1;
 *   DONE  the run ended (after the last rows).
 */
#define _GNU_SOURCE
#include <stdarg.h>

#include "host_platform.h"  /* loading a binary, the platform shim */
#ifdef _WIN32
#include <fcntl.h>
#include <io.h>
#endif

#define MAX_COMPONENTS 8
#define MAX_ITEMS 256

typedef struct {
    char name[64], dir[PATH_SIZE], guid[256], model[256];
    Component c;
    Component (*Instantiate)(const char*, int, const char*, const char*, const Callbacks*, int, int);
    void (*FreeInstance)(Component);
    int (*SetupExperiment)(Component, int, double, double, int, double);
    int (*EnterInitializationMode)(Component), (*ExitInitializationMode)(Component);
    int (*Terminate)(Component);
    int (*SetReal)(Component, const unsigned*, size_t, const double*);
    int (*GetReal)(Component, const unsigned*, size_t, double*);
    int (*SetInteger)(Component, const unsigned*, size_t, const int*);
    int (*SetBoolean)(Component, const unsigned*, size_t, const int*);
    int (*GetBoolean)(Component, const unsigned*, size_t, int*);
    int (*SetString)(Component, const unsigned*, size_t, const char* const*);
    int (*DoStep)(Component, double, double, int);
} Fmu;

typedef struct { int kind, component; unsigned vr; double real; int integer; char* text; } Start;
typedef struct { int source, target; unsigned output, input; } Link;
typedef struct { int boolean, component; unsigned vr; } Column;

static Fmu fmu[MAX_COMPONENTS];
static int components, order[MAX_COMPONENTS], ordered;
static Start start[MAX_ITEMS];
static Link edge[MAX_ITEMS];
static Column column[MAX_ITEMS];
static int starts, links, columns;
static int binary;          /* "binary ROWS": frames on stdout (see the header) */
static double *block, now;  /* the rows not yet written (binary), the time of the step [s] */
static long block_rows, block_size, frame_size;  /* frame_size: ROWS + 1, then ROWS */
typedef struct { int component, boolean, first, count; } Read;  /* columns read in one call */
static Read reads[MAX_ITEMS];
static unsigned read_vr[MAX_ITEMS];
static int n_reads;

/* One frame: a 4-byte tag, the payload's length (4 bytes, little-endian), the payload. */
static void frame(const char* tag, const void* payload, size_t size)
{
    unsigned char head[8];
    memcpy(head, tag, 4);
    for (int i = 0; i < 4; ++i) head[4 + i] = (unsigned char)((size >> (8 * i)) & 0xff);
    fwrite(head, 1, sizeof head, stdout);
    if (size) fwrite(payload, 1, size, stdout);
}

static void flush_rows(void)
{
    if (block_rows) frame("ROWS", block, sizeof(double) * (size_t)(block_rows * columns));
    block_rows = 0;
}

static void logger(void* env, const char* name, int status, const char* category, const char* message, ...)
{
    (void)env;
    char text[8192];
    va_list args;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args); /* the message is a printf format (FMI 2.0) */
    va_end(args);
    if (binary) {
        char entry[8192 + 600];
        int size = snprintf(entry, sizeof entry, "%d %s %s\t%s", status, name && *name ? name : "-",
                            category && *category ? category : "-", text);
        frame("LOG_", entry, size < 0 ? 0 : size < (int)sizeof entry ? (size_t)size : sizeof entry - 1);
        return;
    }
    printf("log %d %s %s ", status, name && *name ? name : "-", category && *category ? category : "-");
    for (const char* p = text; *p; ++p) printf("%02x", (unsigned char)*p);
    if (!*text) putchar('_');
    putchar('\n');
}

static char* unhex(const char* hex)
{
    size_t n = strcmp(hex, "_") ? strlen(hex) / 2 : 0;
    char* out = calloc(n + 1, 1);
    for (size_t i = 0; out && i < n; ++i) sscanf(hex + 2 * i, "%2hhx", (unsigned char*)&out[i]);
    return out;
}

static int bad(const char* what, const char* detail)
{
    fprintf(stderr, "loop_host: %s: %s\n", what, detail);
    exit(2);
}

static int find(const char* name)
{
    for (int i = 0; i < components; ++i)
        if (!strcmp(fmu[i].name, name)) return i;
    return bad("no component", name);
}

static void read_model_description(Fmu* f)
{
    char why[PATH_SIZE + 64];
    if (host_model_description(f->dir, f->guid, f->model, why, sizeof why)) bad("model description", why);
}

static void load(Fmu* f)
{
    char path[2 * PATH_SIZE], why[3 * PATH_SIZE];
    void* library = host_open_library(f->dir, f->model, path, sizeof path, why, sizeof why);
    if (!library) { fprintf(stderr, "loop_host: %s\n", why); exit(1); }
#define SYM(n) if (!(*(void**)&f->n = host_symbol(library, "fmi2" #n))) bad("no fmi2" #n " in", path);
    SYM(Instantiate) SYM(FreeInstance) SYM(SetupExperiment) SYM(EnterInitializationMode)
    SYM(ExitInitializationMode) SYM(Terminate) SYM(SetReal) SYM(GetReal) SYM(SetInteger)
    SYM(SetBoolean) SYM(GetBoolean) SYM(SetString) SYM(DoStep)
#undef SYM
}

/* file:// URI of DIR/resources ("file:///C:/dir/resources" on Windows). */
static void resource_uri(const char* dir, char* uri, size_t size)
{
    char absolute[PATH_SIZE];
    if (!host_absolute_dir(dir, absolute, sizeof absolute)) bad("no absolute path for", dir);
#ifdef _WIN32
    snprintf(uri, size, "file:///%s/resources", absolute);
#else
    snprintf(uri, size, "file://%s/resources", absolute);
#endif
}


static void check(int status, const Fmu* f, const char* call)
{
    if (status > 1) {
        if (binary) {  /* the rows up to this step, then what failed and when */
            char text[512];
            int size = snprintf(text, sizeof text, "%s.%s returned %d at t = %.9g s", f->name, call,
                                status, now);
            flush_rows();
            frame("FAIL", text, size < 0 ? 0 : size < (int)sizeof text ? (size_t)size : sizeof text - 1);
            fflush(stdout);
        }
        fprintf(stderr, "loop_host: %s.%s returned %d\n", f->name, call, status);
        exit(1);
    }
}

/* Each input of component i gets its source's output now. */
static void feed(int i)
{
    for (int k = 0; k < links; ++k) {
        if (edge[k].target != i) continue;
        const Fmu* s = &fmu[edge[k].source];
        double value;
        check(s->GetReal(s->c, &edge[k].output, 1, &value), s, "fmi2GetReal");
        check(fmu[i].SetReal(fmu[i].c, &edge[k].input, 1, &value), &fmu[i], "fmi2SetReal");
    }
}

/* The recorded columns now: a row of the block (written when it is full), or a line. */
static void print_row(void)
{
    if (binary) {
        double* row = block + block_rows * columns;
        for (int r = 0; r < n_reads; ++r) {
            const Read* read = &reads[r];
            const Fmu* f = &fmu[read->component];
            if (read->boolean) {
                int value[MAX_ITEMS];
                check(f->GetBoolean(f->c, &read_vr[read->first], (size_t)read->count, value), f,
                      "fmi2GetBoolean");
                for (int k = 0; k < read->count; ++k) row[read->first + k] = value[k] ? 1.0 : 0.0;
            } else {
                check(f->GetReal(f->c, &read_vr[read->first], (size_t)read->count, &row[read->first]),
                      f, "fmi2GetReal");
            }
        }
        if (++block_rows == frame_size) {
            flush_rows();
            frame_size = block_size;
        }
        return;
    }
    fputs("row", stdout);
    for (int k = 0; k < columns; ++k) {
        const Fmu* f = &fmu[column[k].component];
        if (column[k].boolean) {
            int value;
            check(f->GetBoolean(f->c, &column[k].vr, 1, &value), f, "fmi2GetBoolean");
            printf(" %d", value ? 1 : 0);
        } else {
            double value;
            check(f->GetReal(f->c, &column[k].vr, 1, &value), f, "fmi2GetReal");
            printf(" %.17g", value);
        }
    }
    putchar('\n');
}

static void initialize(double stop, const Callbacks* callbacks)
{
    for (int i = 0; i < components; ++i) {
        Fmu* f = &fmu[i];
        char uri[PATH_SIZE + 64];
        resource_uri(f->dir, uri, sizeof uri);
        f->c = f->Instantiate(f->name, 1, f->guid, uri, callbacks, 0, 0);
        if (!f->c) { fprintf(stderr, "loop_host: %s: fmi2Instantiate returned NULL\n", f->name); exit(1); }
        check(f->SetupExperiment(f->c, 0, 0.0, 0.0, 1, stop), f, "fmi2SetupExperiment");
        check(f->EnterInitializationMode(f->c), f, "fmi2EnterInitializationMode");
    }
    for (int i = 0; i < components; ++i) {
        Fmu* f = &fmu[i];
        for (int k = 0; k < starts; ++k) {
            const Start* s = &start[k];
            if (s->component != i) continue;
            const char* text = s->text;
            int status = s->kind == 0 ? f->SetReal(f->c, &s->vr, 1, &s->real)
                       : s->kind == 1 ? f->SetInteger(f->c, &s->vr, 1, &s->integer)
                       : s->kind == 2 ? f->SetBoolean(f->c, &s->vr, 1, &s->integer)
                       : f->SetString(f->c, &s->vr, 1, &text);
            check(status, f, "fmi2Set (start value)");
        }
        feed(i);
        check(f->ExitInitializationMode(f->c), f, "fmi2ExitInitializationMode");
    }
}

static int by_value(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

static void run(double h, long steps, int timing)
{
    double* cost = timing ? malloc(sizeof(double) * (size_t)steps) : NULL;
    if (timing && !cost) bad("out of memory for", "the timings");
    if (!timing) print_row();
    const double begin = host_now();
    for (long k = 0; k < steps; ++k) {
        const double t = (double)k * h, before = timing ? host_now() : 0.0;
        now = t;
        for (int j = 0; j < ordered; ++j) {
            Fmu* f = &fmu[order[j]];
            feed(order[j]);
            check(f->DoStep(f->c, t, h, 1), f, "fmi2DoStep");
        }
        if (timing) cost[k] = host_now() - before;
        else print_row();
    }
    now = (double)steps * h;
    const double total = host_now() - begin;
    if (binary) {
        flush_rows();
        frame("DONE", NULL, 0);
    }
    if (timing) {
        qsort(cost, (size_t)steps, sizeof(double), by_value);
        printf("timing %.4f %.4f %.4f %.4f %.6f\n", 1e6 * cost[steps / 2],
               1e6 * cost[(long)((double)steps * 0.99)], 1e6 * cost[(long)((double)steps * 0.999)],
               1e6 * cost[steps - 1], total);
        print_row();
        free(cost);
    }
}

/* Binary output (the C master): stdout untranslated, a block of `rows` rows. */
static void start_binary(long rows)
{
    if (rows < 1 || columns < 1) bad("bad binary block size or no recorded column", "run");
#ifdef _WIN32
    _setmode(_fileno(stdout), _O_BINARY);
#endif
    block = malloc(sizeof(double) * (size_t)((rows + 1) * columns));
    if (!block) bad("out of memory for", "the rows");
    block_size = rows;
    frame_size = rows + 1;
    for (int k = 0; k < columns; ++k) {  /* neighbouring columns of one component: one call */
        read_vr[k] = column[k].vr;
        Read* last = n_reads ? &reads[n_reads - 1] : NULL;
        if (last && last->component == column[k].component && last->boolean == column[k].boolean)
            ++last->count;
        else
            reads[n_reads++] = (Read){column[k].component, column[k].boolean, k, 1};
    }
    binary = 1;
}

int main(void)
{
    static char line[1 << 20];
    Callbacks callbacks = {logger, calloc, free, NULL, NULL};
    while (fgets(line, sizeof line, stdin)) {
        char* word[MAX_COMPONENTS + 8];
        int n = 0;
        for (char* p = strtok(line, " \r\n"); p && n < MAX_COMPONENTS + 8; p = strtok(NULL, " \r\n")) word[n++] = p;
        if (n == 0) continue;
        if (!strcmp(word[0], "fmu") && n == 3 && components < MAX_COMPONENTS) {
            Fmu* f = &fmu[components++];
            snprintf(f->name, sizeof f->name, "%s", word[1]);
            snprintf(f->dir, sizeof f->dir, "%s", word[2]);
            read_model_description(f);
            load(f);
        } else if ((!strcmp(word[0], "real") || !strcmp(word[0], "integer") || !strcmp(word[0], "boolean")
                    || !strcmp(word[0], "string")) && n == 4 && starts < MAX_ITEMS) {
            Start* s = &start[starts++];
            s->kind = word[0][0] == 'r' ? 0 : word[0][0] == 'i' ? 1 : word[0][0] == 'b' ? 2 : 3;
            s->component = find(word[1]);
            s->vr = (unsigned)strtoul(word[2], NULL, 10);
            s->real = strtod(word[3], NULL);
            s->integer = (int)strtol(word[3], NULL, 10);
            s->text = s->kind == 3 ? unhex(word[3]) : NULL;
        } else if (!strcmp(word[0], "connect") && n == 5 && links < MAX_ITEMS) {
            edge[links++] = (Link){find(word[1]), find(word[3]), (unsigned)strtoul(word[2], NULL, 10),
                                   (unsigned)strtoul(word[4], NULL, 10)};
        } else if (!strcmp(word[0], "order") && n - 1 <= MAX_COMPONENTS) {
            for (ordered = 0; ordered < n - 1; ++ordered) order[ordered] = find(word[ordered + 1]);
        } else if (!strcmp(word[0], "record") && n == 4 && columns < MAX_ITEMS) {
            column[columns++] = (Column){!strcmp(word[1], "boolean"), find(word[2]),
                                         (unsigned)strtoul(word[3], NULL, 10)};
        } else if (!strcmp(word[0], "run") && (n == 3 || (n == 4 && !strcmp(word[3], "timing"))
                                                || (n == 5 && !strcmp(word[3], "binary")))) {
            const double h = strtod(word[1], NULL);
            const long steps = atol(word[2]);
            if (!(h > 0.0) || steps < 1 || ordered != components) bad("bad run line or step order", word[1]);
            if (n == 5) start_binary(atol(word[4]));
            initialize((double)steps * h, &callbacks);
            run(h, steps, n == 4);
            for (int i = 0; i < components; ++i) {
                check(fmu[i].Terminate(fmu[i].c), &fmu[i], "fmi2Terminate");
                fmu[i].FreeInstance(fmu[i].c);
            }
            fflush(stdout);
            return 0;
        } else {
            bad("bad line", word[0]);
        }
    }
    return bad("no run line", "stdin");
}
