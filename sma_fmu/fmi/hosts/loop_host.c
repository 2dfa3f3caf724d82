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
 *   load DIR                       (a session) load the FMU in DIR now; answers LOAD
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
 *         after the rows up to that step: the run ends there (see the session);
 *   DONE  the run ended (after the last rows; its instances terminated): one double, the
 *         seconds it spent writing the CSV (0 without a csv line);
 *   LOAD  (no payload) the answer to a "load" line: that FMU is loaded.
 * A session (the C master's runs in one process): after a "binary" run the host reads the
 * next system from stdin instead of exiting, until stdin closes (then it frees every
 * instance and exits 0). Each FMU folder is loaded once per process ("load DIR" loads it
 * ahead and answers a LOAD frame, so start-up and runs can be timed apart); its instance
 * is kept across runs and reset (fmi2Reset) before the next one instead of freed, then set
 * up, given the new run's start values and initialized as a new one is. A failed call
 * (FAIL frame) ends only its run: that run's instances are freed, and the next run makes
 * new ones; fmi2Fatal (the FMU's state unusable) ends the process with status 1.
 * "csv PATH EVERY LAST SPEC..." (before the run line, with "binary"): the host also appends the
 * loop's rows as CSV text to PATH (hex; its header already written), every EVERY-th row and
 * row LAST (the final one), each number as Python's "%.10g" writes it (format_g10), the
 * row's columns given by SPEC, one word each: "t" the time k STEP_S; "s:I" recorded column I
 * now; "a:I" column I after the step (the final row: nan); "b:I" a Boolean after the step
 * (the final row: 0); "x:I" the stroke, column I at t_0 minus now; "c:V" the number V; "k:V"
 * the number V after the step (the final row: nan). A row
 * is written when the sample after its step comes, the final row at the end of the run or
 * at a failed call (before its FAIL frame).
 * "g10 HEX..." (a test of format_g10): prints each double (its 16 hex digits of IEEE bits)
 * as "%.10g" would, one a line, and exits.
 */
#define _GNU_SOURCE
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>

#include "host_platform.h"  /* loading a binary, the platform shim */
#ifdef _WIN32
#include <fcntl.h>
#include <io.h>
#endif

#define MAX_COMPONENTS 8
#define MAX_ITEMS 256

typedef struct {
    char name[64], dir[PATH_SIZE], guid[256], model[256];
    fmi2Component c;   /* the instance (NULL: none yet, or freed after a failed run) */
    HOST_FMI2_FUNCTIONS(HOST_FMI2_POINTER)  /* its functions (host_platform.h) */
} Fmu;

typedef struct { int kind, component; unsigned vr; double real; int integer; char* text; } Start;
typedef struct { int source, target; unsigned output, input; } Link;
typedef struct { int boolean, component; unsigned vr; } Column;

#define MAX_LOADED 16
static Fmu loaded[MAX_LOADED];     /* every FMU folder this process loaded (a session's) */
static int n_loaded, session;      /* session: a "load" or "binary" line came */
static Fmu* fmu[MAX_COMPONENTS];   /* this run's components, in the order of their fmu lines */
static int components, order[MAX_COMPONENTS], ordered;
static int failed;                 /* a call of this run failed (binary: FAIL sent) */
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

/* "csv": the rows as text (see the header) */
typedef struct { char kind; int index; double value; uint64_t bits; int size; char text[40]; } CsvColumn;
static CsvColumn csv[MAX_ITEMS];
static int csv_columns, csv_have_prev;
static FILE* csv_file;
static char csv_path[PATH_SIZE];
static long csv_every, csv_last, csv_row;
static double csv_step, csv_x0, csv_prev[MAX_ITEMS];
static double csv_seconds;  /* [s] this run spent writing the CSV (DONE's payload) */
static char* csv_buffer;
static size_t csv_used;
#define CSV_BUFFER (1u << 20)

/* One frame: a 4-byte tag, the payload's length (4 bytes, little-endian), the payload. */
static void frame(const char* tag, const void* payload, size_t size)
{
    unsigned char head[8];
    memcpy(head, tag, 4);
    for (int i = 0; i < 4; ++i) head[4 + i] = (unsigned char)((size >> (8 * i)) & 0xff);
    fwrite(head, 1, sizeof head, stdout);
    if (size) fwrite(payload, 1, size, stdout);
}

/* --- "%.10g" as Python (and a C library) writes it, several times faster than snprintf ---
 * The ten significant digits are the correctly rounded ones (ties to even, as both do):
 * - 1e-10 <= |v| < 1e10 (nearly every number of a run): exactly, in integers. |v| is
 *   m 2^q (m < 2^53); N = m 10^p 2^q with p = 9 - e <= 19 fits 128 bits, and the bits
 *   shifted out say how to round;
 * - 1e-30 <= |v| < 1e-10 or 1e10 <= |v| < 1e30: |v| 10^p in long double (64-bit mantissa:
 *   an error near 1e-9 of a unit of the last digit), rounded; where that lies within 1e-4
 *   of a half, snprintf decides;
 * - otherwise snprintf.
 * Non-finite numbers as Python writes them: nan (never -nan), inf, -inf. */
__extension__ typedef unsigned __int128 Wide;   /* gcc and mingw-w64 on 64-bit targets */
static long double tens[81];  /* tens[i] = 10^(i - 40) */

static void init_tens(void)
{
    long double up = 1.0L;
    for (int i = 40; i <= 80; ++i, up *= 10.0L) tens[i] = up;   /* exact up to 10^27 */
    for (int i = 39; i >= 0; --i) tens[i] = 1.0L / tens[80 - i];
}

static int format_fallback(double v, char* out)
{
    int size = snprintf(out, 40, "%.10g", v);
    return size < 0 ? 0 : size;
}

/* N = round(m 2^q 10^p) exactly (0 <= p <= 19, q < 0, -q < 128 - 117). */
static uint64_t scaled_exact(uint64_t m, int q, int p)
{
    static const uint64_t ten[20] = {1ULL, 10ULL, 100ULL, 1000ULL, 10000ULL, 100000ULL, 1000000ULL,
        10000000ULL, 100000000ULL, 1000000000ULL, 10000000000ULL, 100000000000ULL,
        1000000000000ULL, 10000000000000ULL, 100000000000000ULL, 1000000000000000ULL,
        10000000000000000ULL, 100000000000000000ULL, 1000000000000000000ULL,
        10000000000000000000ULL};
    const Wide x = (Wide)m * ten[p];
    if (q >= 0) return (uint64_t)(x << q);
    const int s = -q;
    const Wide rest = x & (((Wide)1 << s) - 1), half = (Wide)1 << (s - 1);
    uint64_t n = (uint64_t)(x >> s);
    if (rest > half || (rest == half && (n & 1))) ++n;
    return n;
}

static int format_g10(double v, char* out)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    const int negative = (int)(bits >> 63), biased = (int)((bits >> 52) & 0x7ff);
    if (biased == 0x7ff) {
        if (bits & 0xfffffffffffffULL) { memcpy(out, "nan", 3); return 3; }
        if (negative) { memcpy(out, "-inf", 4); return 4; }
        memcpy(out, "inf", 3);
        return 3;
    }
    if (v == 0.0) {
        if (negative) { memcpy(out, "-0", 2); return 2; }
        out[0] = '0';
        return 1;
    }
    if (biased == 0) return format_fallback(v, out);  /* subnormal */
    const uint64_t m = (bits & 0xfffffffffffffULL) | (1ULL << 52);
    const int q = biased - 1075;
    /* e: the decimal exponent, 10^e <= |v| < 10^(e+1); first a guess from the binary one
     * (q + 52 = floor(log2 |v|); 78913 / 2^18 = log10 2 to 6 digits), then corrected */
    const int t = (q + 52) * 78913;
    int e = t >= 0 ? t >> 18 : -((-t + (1 << 18) - 1) >> 18);
    uint64_t n = 0;
    for (int tries = 0;; ++tries) {
        if (tries == 4) return format_fallback(v, out);
        const int p = 9 - e;
        if (p >= 0 && p <= 19 && q < 0 && -q <= 11 + 64 + 30) {
            n = scaled_exact(m, q, p);
        } else {
            if (LDBL_MANT_DIG < 64 || p < -20 || p > 40) return format_fallback(v, out);
            const long double scaled = (negative ? -(long double)v : (long double)v) * tens[p + 40];
            if (!(scaled >= 999999999.0L && scaled < 1e10L)) {
                n = scaled < 999999999.0L ? 0 : 10000000000ULL;  /* retried below */
            } else {
                n = (uint64_t)scaled;
                const long double fraction = scaled - (long double)n;
                if (fraction > 0.4999L && fraction < 0.5001L) return format_fallback(v, out);
                if (fraction > 0.5L) ++n;
            }
        }
        if (n < 1000000000ULL) { --e; continue; }       /* e was too high */
        if (n >= 10000000000ULL) { ++e; continue; }     /* too low, or rounded up to 10^10 */
        break;
    }
    char digits[10];
    uint32_t high = (uint32_t)(n / 100000), low = (uint32_t)(n % 100000);
    for (int i = 9; i >= 5; --i) { digits[i] = (char)('0' + low % 10); low /= 10; }
    for (int i = 4; i >= 0; --i) { digits[i] = (char)('0' + high % 10); high /= 10; }
    int last = 9;   /* the last significant digit kept (trailing zeros go, as %g does) */
    while (last > 0 && digits[last] == '0') --last;
    char* o = out;
    if (negative) *o++ = '-';
    if (e < -4 || e >= 10) {
        *o++ = digits[0];
        if (last > 0) {
            *o++ = '.';
            memcpy(o, digits + 1, (size_t)last);
            o += last;
        }
        *o++ = 'e';
        *o++ = e < 0 ? '-' : '+';
        const int x = e < 0 ? -e : e;
        if (x >= 100) *o++ = (char)('0' + x / 100);
        *o++ = (char)('0' + x / 10 % 10);
        *o++ = (char)('0' + x % 10);
    } else if (e >= 0) {
        memcpy(o, digits, (size_t)e + 1);
        o += e + 1;
        if (last > e) {
            *o++ = '.';
            memcpy(o, digits + e + 1, (size_t)(last - e));
            o += last - e;
        }
    } else {
        *o++ = '0';
        *o++ = '.';
        for (int i = 0; i < -e - 1; ++i) *o++ = '0';
        memcpy(o, digits, (size_t)last + 1);
        o += last + 1;
    }
    return (int)(o - out);
}

static void csv_flush(void)
{
    if (csv_used && fwrite(csv_buffer, 1, csv_used, csv_file) != csv_used) {
        fprintf(stderr, "loop_host: cannot write the CSV file %s\n", csv_path);
        exit(1);
    }
    csv_used = 0;
}

/* Row csv_row: the sample `now` and the one after its step (NULL: the final row). */
static void csv_write(const double* now, const double* after)
{
    const long row = csv_row++;
    if (row % csv_every != 0 && row != csv_last) return;
    if (csv_used + (size_t)csv_columns * 40 > CSV_BUFFER) csv_flush();
    char* p = csv_buffer + csv_used;
    for (int k = 0; k < csv_columns; ++k) {
        CsvColumn* c = &csv[k];
        double v;
        switch (c->kind) {
        case 't': v = (double)row * csv_step; break;
        case 's': v = now[c->index]; break;
        case 'a': v = after ? after[c->index] : NAN; break;
        case 'b': v = after && after[c->index] != 0.0 ? 1.0 : 0.0; break;
        case 'x': v = csv_x0 - now[c->index]; break;
        case 'k': v = after ? c->value : NAN; break;
        default: v = c->value; break;
        }
        uint64_t bits;
        memcpy(&bits, &v, sizeof bits);
        if (!c->size || bits != c->bits) {  /* a column that holds still is formatted once */
            c->bits = bits;
            c->size = format_g10(v, c->text);
        }
        if (k) *p++ = ',';
        memcpy(p, c->text, (size_t)c->size);
        p += c->size;
    }
    *p++ = '\n';
    csv_used = (size_t)(p - csv_buffer);
}

/* A recorded sample (after initialization or a step): completes the row before it. */
static void csv_sample(const double* sample)
{
    if (csv_have_prev) csv_write(csv_prev, sample);
    else {
        for (int k = 0; k < csv_columns; ++k)
            if (csv[k].kind == 'x') csv_x0 = sample[csv[k].index];
    }
    memcpy(csv_prev, sample, sizeof(double) * (size_t)columns);
    csv_have_prev = 1;
}

/* The end of the rows (the run's, or a failed call's): the last sample as the final row. */
static void csv_finish(void)
{
    if (!csv_file) return;
    if (csv_have_prev) csv_write(csv_prev, NULL);
    csv_have_prev = 0;
    csv_flush();
    if (fclose(csv_file)) {
        fprintf(stderr, "loop_host: cannot write the CSV file %s\n", csv_path);
        exit(1);
    }
    csv_file = NULL;
}

static void flush_rows(void)
{
    if (block_rows) frame("ROWS", block, sizeof(double) * (size_t)(block_rows * columns));
    block_rows = 0;
}

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
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

static int hex_digit(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
         : c >= 'A' && c <= 'F' ? c - 'A' + 10 : 0;
}

/* decoded by hand: sscanf per byte measures the rest of the string each call, quadratic in
 * a long String start value (a stroke scenario's R_ref table: 1 MB of hex took 17 s) */
static char* unhex(const char* hex)
{
    size_t n = strcmp(hex, "_") ? strlen(hex) / 2 : 0;
    char* out = calloc(n + 1, 1);
    for (size_t i = 0; out && i < n; ++i)
        out[i] = (char)(hex_digit(hex[2 * i]) << 4 | hex_digit(hex[2 * i + 1]));
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
        if (!strcmp(fmu[i]->name, name)) return i;
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
    HOST_FMI2_FUNCTIONS(SYM)
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


/* 0 when `status` is fmi2OK or fmi2Warning. Else, in binary mode, the rows up to this step,
 * then what failed and when (FAIL), and 1: the run ends there (`failed`), the session goes
 * on, but for fmi2Fatal; otherwise (and for fmi2Fatal) the host exits with status 1. */
static int check(int status, const Fmu* f, const char* call)
{
    if (status <= 1) return 0;
    if (binary) {
        char text[512];
        int size = snprintf(text, sizeof text, "%s.%s returned %d at t = %.9g s", f->name, call,
                            status, now);
        csv_finish();
        flush_rows();
        frame("FAIL", text, size < 0 ? 0 : size < (int)sizeof text ? (size_t)size : sizeof text - 1);
        fflush(stdout);
        failed = 1;
        if (status < 4) return 1;
    }
    fprintf(stderr, "loop_host: %s.%s returned %d\n", f->name, call, status);
    exit(1);
}

/* Each input of component i gets its source's output now. */
static void feed(int i)
{
    for (int k = 0; k < links; ++k) {
        if (edge[k].target != i) continue;
        const Fmu* s = fmu[edge[k].source];
        double value;
        if (check(s->GetReal(s->c, &edge[k].output, 1, &value), s, "fmi2GetReal")
            || check(fmu[i]->SetReal(fmu[i]->c, &edge[k].input, 1, &value), fmu[i], "fmi2SetReal"))
            return;
    }
}

/* The recorded columns now: a row of the block (written when it is full), or a line. */
static void print_row(void)
{
    if (binary) {
        double* row = block + block_rows * columns;
        for (int r = 0; r < n_reads; ++r) {
            const Read* read = &reads[r];
            const Fmu* f = fmu[read->component];
            if (read->boolean) {
                int value[MAX_ITEMS];
                if (check(f->GetBoolean(f->c, &read_vr[read->first], (size_t)read->count, value), f,
                          "fmi2GetBoolean")) return;
                for (int k = 0; k < read->count; ++k) row[read->first + k] = value[k] ? 1.0 : 0.0;
            } else if (check(f->GetReal(f->c, &read_vr[read->first], (size_t)read->count,
                                        &row[read->first]), f, "fmi2GetReal")) {
                return;
            }
        }
        if (csv_file) {
            const double begin = host_now();
            csv_sample(row);
            csv_seconds += host_now() - begin;
        }
        if (++block_rows == frame_size) {
            flush_rows();
            frame_size = block_size;
        }
        return;
    }
    fputs("row", stdout);
    for (int k = 0; k < columns; ++k) {
        const Fmu* f = fmu[column[k].component];
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

static void initialize(double stop, const fmi2CallbackFunctions* callbacks)
{
    for (int i = 0; i < components; ++i) {
        Fmu* f = fmu[i];
        if (f->c && f->Reset(f->c) > 1) {  /* an earlier run's instance: reset, else a new one */
            f->FreeInstance(f->c);
            f->c = NULL;
        }
        if (!f->c) {
            char uri[PATH_SIZE + 64];
            resource_uri(f->dir, uri, sizeof uri);
            f->c = f->Instantiate(f->name, fmi2CoSimulation, f->guid, uri, callbacks, fmi2False, fmi2False);
            if (!f->c) { fprintf(stderr, "loop_host: %s: fmi2Instantiate returned NULL\n", f->name); exit(1); }
        }
        if (check(f->SetupExperiment(f->c, 0, 0.0, 0.0, 1, stop), f, "fmi2SetupExperiment")
            || check(f->EnterInitializationMode(f->c), f, "fmi2EnterInitializationMode"))
            return;
    }
    for (int i = 0; i < components; ++i) {
        Fmu* f = fmu[i];
        for (int k = 0; k < starts; ++k) {
            const Start* s = &start[k];
            if (s->component != i) continue;
            const char* text = s->text;
            int status = s->kind == 0 ? f->SetReal(f->c, &s->vr, 1, &s->real)
                       : s->kind == 1 ? f->SetInteger(f->c, &s->vr, 1, &s->integer)
                       : s->kind == 2 ? f->SetBoolean(f->c, &s->vr, 1, &s->integer)
                       : f->SetString(f->c, &s->vr, 1, &text);
            if (check(status, f, "fmi2Set (start value)")) return;
        }
        feed(i);
        if (failed || check(f->ExitInitializationMode(f->c), f, "fmi2ExitInitializationMode")) return;
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
    for (long k = 0; k < steps && !failed; ++k) {
        const double t = (double)k * h, before = timing ? host_now() : 0.0;
        now = t;
        for (int j = 0; j < ordered; ++j) {
            Fmu* f = fmu[order[j]];
            feed(order[j]);
            if (failed || check(f->DoStep(f->c, t, h, 1), f, "fmi2DoStep")) return;
        }
        if (timing) cost[k] = host_now() - before;
        else print_row();
    }
    if (failed) return;
    now = (double)steps * h;
    const double total = host_now() - begin;
    if (binary) {   /* DONE follows when the instances have terminated (end_run) */
        const double begin = host_now();
        csv_finish();
        csv_seconds += host_now() - begin;
        flush_rows();
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

/* Frames on stdout from now on (untranslated on Windows): the C master's session. */
static void start_session(void)
{
#ifdef _WIN32
    if (!session) _setmode(_fileno(stdout), _O_BINARY);
#endif
    session = 1;
}

/* Binary output (the C master): stdout untranslated, a block of `rows` rows. */
static void start_binary(long rows)
{
    if (rows < 1 || columns < 1) bad("bad binary block size or no recorded column", "run");
    start_session();
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

/* "csv PATH EVERY LAST SPEC..." (see the header): open PATH to append the rows' text. */
static void start_csv(char** word, int n)
{
    char* path = unhex(word[1]);
    if (!path) bad("out of memory for", "the CSV path");
    snprintf(csv_path, sizeof csv_path, "%s", path);
    free(path);
    csv_every = atol(word[2]);
    csv_last = atol(word[3]);
    if (csv_every < 1 || n - 4 > MAX_ITEMS) bad("bad csv line", word[2]);
    for (int k = 4; k < n; ++k) {
        CsvColumn* c = &csv[csv_columns++];
        const char* spec = word[k];
        c->kind = spec[0];
        if (c->kind == 't') continue;
        if (spec[1] != ':' || !strchr("sabxck", c->kind)) bad("bad csv column", spec);
        if (c->kind == 'c' || c->kind == 'k') {
            c->value = !strcmp(spec + 2, "nan") ? NAN : strtod(spec + 2, NULL);
        } else {
            c->index = atoi(spec + 2);
            if (c->index < 0 || c->index >= columns) bad("csv column out of the recorded ones", spec);
        }
    }
    if (!csv_buffer) csv_buffer = malloc(CSV_BUFFER);   /* kept for a session's next runs */
    if (!csv_buffer) bad("out of memory for", "the CSV rows");
    csv_file = fopen(csv_path, "ab");
    if (!csv_file) bad("cannot open the CSV file", csv_path);
}

/* "g10 HEX..." (see the header). */
static void print_g10(char* values)
{
    for (char* word = strtok(values, " \r\n"); word; word = strtok(NULL, " \r\n")) {
        uint64_t bits = (uint64_t)strtoull(word, NULL, 16);
        double v;
        char text[48];
        memcpy(&v, &bits, sizeof v);
        text[format_g10(v, text)] = '\0';
        puts(text);
    }
    fflush(stdout);
}

/* The loaded FMU of folder `dir`: loaded now (model description, binary) or before. */
static Fmu* loaded_fmu(const char* dir)
{
    for (int i = 0; i < n_loaded; ++i)
        if (!strcmp(loaded[i].dir, dir)) return &loaded[i];
    if (n_loaded == MAX_LOADED) bad("more FMU folders than the host keeps loaded", dir);
    Fmu* f = &loaded[n_loaded++];
    snprintf(f->dir, sizeof f->dir, "%s", dir);
    read_model_description(f);
    load(f);
    return f;
}

/* "fmu NAME DIR": the component NAME of this run, the FMU in DIR (its instance kept from an
 * earlier run of the session if it had this name). */
static void add_component(const char* name, const char* dir)
{
    Fmu* f = loaded_fmu(dir);
    for (int i = 0; i < components; ++i)
        if (fmu[i] == f) bad("one FMU folder for two components", dir);
    if (f->c && strcmp(f->name, name)) {  /* the instance's name was another: a new one */
        f->FreeInstance(f->c);
        f->c = NULL;
    }
    snprintf(f->name, sizeof f->name, "%s", name);
    fmu[components++] = f;
}

/* After a binary run: its instances terminated (kept for the next run) and DONE, or freed
 * when a call failed (FAIL was sent); the system's lines forgotten, ready for the next. */
static void end_run(void)
{
    for (int i = 0; i < components && !failed; ++i)
        check(fmu[i]->Terminate(fmu[i]->c), fmu[i], "fmi2Terminate");
    if (!failed) frame("DONE", &csv_seconds, sizeof csv_seconds);
    for (int i = 0; i < components && failed; ++i) {
        if (fmu[i]->c) fmu[i]->FreeInstance(fmu[i]->c);
        fmu[i]->c = NULL;
    }
    for (int k = 0; k < starts; ++k) free(start[k].text);
    starts = links = columns = ordered = components = n_reads = failed = 0;
    free(block);
    block = NULL;
    block_rows = 0;
    csv_columns = csv_have_prev = 0;
    csv_seconds = 0.0;
    csv_row = 0;
}

int main(void)
{
    /* a line holds a String start value hex-coded: up to twice the runtime's JSON_TEXT_MAX_BYTES
     * (8 MiB), e.g. a stroke scenario's R_ref table, one knot per step */
    static char line[(1 << 24) + (1 << 20)];
    /* stdout written 1 MiB at a time (the pipe's size): the master wakes once per MiB of
     * rows, not once per 4 KiB (on a busy machine each wake-up waits for a core) */
    setvbuf(stdout, NULL, _IOFBF, 1 << 20);
    init_tens();
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    while (fgets(line, sizeof line, stdin)) {
        if (!strncmp(line, "g10 ", 4)) {
            print_g10(line + 4);
            return 0;
        }
        char* word[MAX_ITEMS + 8];
        int n = 0;
        for (char* p = strtok(line, " \r\n"); p && n < MAX_ITEMS + 8; p = strtok(NULL, " \r\n")) word[n++] = p;
        if (n == 0) continue;
        if (!strcmp(word[0], "fmu") && n == 3 && components < MAX_COMPONENTS) {
            add_component(word[1], word[2]);
        } else if (!strcmp(word[0], "load") && n == 2) {   /* a session's start-up: answers LOAD */
            start_session();
            loaded_fmu(word[1]);
            frame("LOAD", NULL, 0);
            fflush(stdout);
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
        } else if (!strcmp(word[0], "csv") && n >= 5 && !csv_file) {
            start_csv(word, n);
        } else if (!strcmp(word[0], "run") && (n == 3 || (n == 4 && !strcmp(word[3], "timing"))
                                                || (n == 5 && !strcmp(word[3], "binary")))) {
            const double h = strtod(word[1], NULL);
            const long steps = atol(word[2]);
            if (!(h > 0.0) || steps < 1 || ordered != components) bad("bad run line or step order", word[1]);
            if (csv_file && n != 5) bad("a csv line needs", "run ... binary ROWS");
            csv_step = h;
            if (n == 5) start_binary(atol(word[4]));
            now = 0.0;   /* a failure before the first step is at t = 0 */
            initialize((double)steps * h, &callbacks);
            if (!failed) run(h, steps, n == 4);
            if (binary) {   /* a session: the next system follows on stdin */
                end_run();
                fflush(stdout);
                continue;
            }
            for (int i = 0; i < components; ++i) {
                check(fmu[i]->Terminate(fmu[i]->c), fmu[i], "fmi2Terminate");
                fmu[i]->FreeInstance(fmu[i]->c);
            }
            fflush(stdout);
            return 0;
        } else {
            bad("bad line", word[0]);
        }
    }
    if (!session) return bad("no run line", "stdin");
    for (int i = 0; i < n_loaded; ++i)   /* stdin closed: the session ends */
        if (loaded[i].c) loaded[i].FreeInstance(loaded[i].c);
    return 0;
}
