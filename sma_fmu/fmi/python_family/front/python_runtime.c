/*
 * python_runtime.c - what the front does with the Python the backend runs in, on every
 * platform: check its version, keep one thread state per host thread, serialize first
 * initializations, and take pythonfmu's sys.path entry away after each instantiation.
 * Finding and loading that Python is platform code (libpython_posix.c, libpython_windows.c).
 *
 * pythonfmu takes the GIL with PyGILState_Ensure/Release around every call. In a thread
 * Python does not know, that creates and deletes a Python thread state per call (an mmap
 * and munmap each time). keep_thread_state() creates one per host thread on its first call
 * and parks it, so pythonfmu's calls reuse it; it is released when the thread exits.
 * SMA_FMU_NO_TSTATE=1 switches this off (for measurements).
 *
 * No Python header is needed: the few C-API functions used are looked up by name.
 */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"

int use_thread_state_keeper = 1;

static struct {
    int (*IsInitialized)(void);
    int (*GILState_Ensure)(void); /* PyGILState_STATE is an int-sized enum */
    void (*GILState_Release)(int);
    void* (*GILState_GetThisThreadState)(void);
    void* (*Eval_SaveThread)(void);
    void (*Eval_RestoreThread)(void*);
    int (*IsFinalizing)(void); /* Py_IsFinalizing (3.13+) or _Py_IsFinalizing; may be NULL */
    void (*ThreadState_Clear)(void*);
    void (*ThreadState_DeleteCurrent)(void);
    /* taking a folder off sys.path (all in the stable ABI; Py_ssize_t is ptrdiff_t) */
    void* (*Import_ImportModule)(const char*);
    void* (*Object_GetAttrString)(void*, const char*);
    void* (*Unicode_FromString)(const char*);
    ptrdiff_t (*List_Size)(void*);
    void* (*List_GetItem)(void*, ptrdiff_t);
    int (*Object_RichCompareBool)(void*, void*, int);
    int (*Sequence_DelItem)(void*, ptrdiff_t);
    int (*Object_DelItem)(void*, void*);
    void (*Err_Clear)(void);
    void (*DecRef)(void*);
    /* the direct doStep (fast_path.c); the last argument is always NULL (no keywords), so
     * PyObject_VectorcallDict serves where PyObject_Vectorcall is not exported */
    void* (*Object_Vectorcall)(void*, void* const*, size_t, void*);
    void* (*Float_FromDouble)(double);
    void* (*Long_FromLong)(long);
    void* (*Bool_FromLong)(long);
    double (*Float_AsDouble)(void*);
    ptrdiff_t (*Tuple_Size)(void*);
    void* (*Tuple_GetItem)(void*, ptrdiff_t);
    void* (*Err_Occurred)(void);
    void* None;
    int (*Object_IsTrue)(void*);
    void (*Err_Print)(void);
} py;

#define PY_EQ 2
#define PYTHON_THREAD ((void*)1) /* the thread slot's mark: a thread with its own Python state */

static int python_is_initialized(void) { return py.IsInitialized && py.IsInitialized(); }

/* ---- one parked thread state per host thread ----------------------------------------------- */
/* At thread exit. Not through PyGILState_Release: the C library may already have cleared
 * Python's own thread-specific slot of the exiting thread. Instead do what
 * PyGILState_Release does at counter 0. Skipped once Python is finalizing. */
static void release_kept_state(void* kept)
{
    if (!kept || kept == PYTHON_THREAD) return;
    if (py.ThreadState_Clear && py.ThreadState_DeleteCurrent && python_is_initialized() &&
        !(py.IsFinalizing && py.IsFinalizing())) {
        py.Eval_RestoreThread(kept);   /* takes the GIL */
        py.ThreadState_Clear(kept);
        py.ThreadState_DeleteCurrent(); /* deletes it and releases the GIL */
    }
}

static void owner_keep_thread_state(void)
{
    if (!use_thread_state_keeper || thread_slot_get() || !python_is_initialized()) return;
    if (py.GILState_GetThisThreadState()) { /* a Python thread: nothing to do */
        thread_slot_set(PYTHON_THREAD);
        return;
    }
    py.GILState_Ensure();               /* a new thread state, GIL taken */
    void* state = py.Eval_SaveThread(); /* GIL released, state kept (Ensure counter 1) */
    thread_slot_set(state);
}

/* pythonfmu initializes Python in its first fmi2Instantiate, guarded by a mutex private to
 * each copy of pythonfmu's binary: two different FMUs instantiated at the same moment can
 * both call Py_Initialize and crash. Fronts share no memory, but they share the Python
 * library file: a lock on it serializes first instantiations until Python is initialized. */
static fmi2Component owner_instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                       fmi2String uri, const fmi2CallbackFunctions* cb,
                                       fmi2Boolean visible)
{
    /* loggingOn = true: pythonfmu would drop every message otherwise; the front filters */
    if (python_is_initialized()) return backend.Instantiate(name, type, guid, uri, cb, visible, 1);
    char file[PATH_SIZE];
    void* lock = python_library_file(file, sizeof file) ? lock_file(file) : NULL;
    fmi2Component component = backend.Instantiate(name, type, guid, uri, cb, visible, 1);
    unlock_file(lock);
    return component;
}

/* pythonfmu puts each instance's resources folder first on sys.path and never takes it off:
 * one entry per instance, each searched by every later import, long after the folder is
 * gone. The slave has imported all it needs when it is created, so the entry goes again. */
static void owner_forget_resources(const char* folder)
{
    if (!py.Import_ImportModule || !py.Object_GetAttrString || !py.Unicode_FromString ||
        !py.List_Size || !py.List_GetItem || !py.Object_RichCompareBool || !py.Sequence_DelItem ||
        !py.Object_DelItem || !py.Err_Clear || !py.DecRef || !py.GILState_Release ||
        !python_is_initialized())
        return;
    int gil = py.GILState_Ensure();
    void* sys = py.Import_ImportModule("sys");
    void* path = sys ? py.Object_GetAttrString(sys, "path") : NULL;
    void* key = py.Unicode_FromString(folder);
    if (path && key) {
        ptrdiff_t n = py.List_Size(path);
        for (ptrdiff_t i = 0; i < n; ++i) {
            void* entry = py.List_GetItem(path, i); /* borrowed */
            if (entry && py.Object_RichCompareBool(entry, key, PY_EQ) == 1) {
                py.Sequence_DelItem(path, i); /* the one entry pythonfmu put there */
                break;
            }
        }
        void* cache = py.Object_GetAttrString(sys, "path_importer_cache");
        if (cache) {
            py.Object_DelItem(cache, key); /* a KeyError when no import looked there */
            py.DecRef(cache);
        }
    }
    py.Err_Clear();
    if (key) py.DecRef(key);
    if (path) py.DecRef(path);
    if (sys) py.DecRef(sys);
    py.GILState_Release(gil);
}

/* A Python object for input i of a direct step: its value, or None if it is not pending;
 * NULL if out of memory. */
static void* step_input(const StepCall* call, size_t i)
{
    int slot = call->input_slots[i];
    if (!call->pending || call->pending[slot] == 0.0) return py.None;
    double value = call->values[slot];
    char kind = call->input_kinds[i];
    if (kind == 'I') return py.Long_FromLong((long)value); /* an fmi2Integer, exact */
    if (kind == 'B') return py.Bool_FromLong(value != 0.0);
    return py.Float_FromDouble(value);
}

/* The slave's direct step (fast_path.c, StepCall): step(t, h, inputs...) under the GIL. An
 * exception cannot come from the step (it catches Exception); anything else (a
 * KeyboardInterrupt) is printed as Python would and cleared, and the call says -1. */
static int owner_call_step(void* callable, void* queue, long* queued, const StepCall* call)
{
    int gil = py.GILState_Ensure();
    void* args[2 + STEP_MAX_INPUTS];
    size_t n = 0, count = 2 + call->n_inputs;
    args[n++] = py.Float_FromDouble(call->t);
    args[n++] = py.Float_FromDouble(call->h);
    while (n < count && args[0] && args[1] && (args[n] = step_input(call, n - 2))) ++n;
    void* result = n == count && args[0] && args[1]
                   ? py.Object_Vectorcall(callable, args, count, NULL) : NULL;
    for (size_t i = 0; i < n; ++i)
        if (args[i] && args[i] != py.None) py.DecRef(args[i]);
    int outcome = -1;
    if (result) {
        ptrdiff_t size = py.Tuple_Size(result);
        if (size < 0) { /* no tuple: the slave wrote the buffer, the result says done */
            py.Err_Clear();
            outcome = py.Object_IsTrue(result);
        } else {
            outcome = (size_t)size == call->n_changed ? 2 : 3;
            for (ptrdiff_t i = 0; outcome == 2 && i < size; ++i) {
                double value = py.Float_AsDouble(py.Tuple_GetItem(result, i));
                if (value == -1.0 && py.Err_Occurred()) {
                    py.Err_Clear();
                    outcome = 3;
                }
                call->changed[i] = value;
            }
        }
        py.DecRef(result);
    }
    if (outcome < 0) py.Err_Print();
    ptrdiff_t size = queue ? py.List_Size(queue) : 1;
    if (size < 0) py.Err_Clear();
    *queued = size < 0 ? 1 : (long)size;
    py.GILState_Release(gil);
    return outcome;
}

int start_python_runtime(RuntimeCalls* calls)
{
#define LOOKUP(field, name) *(void**)(&py.field) = python_symbol(name)
    LOOKUP(IsInitialized, "Py_IsInitialized");
    LOOKUP(GILState_Ensure, "PyGILState_Ensure");
    LOOKUP(GILState_Release, "PyGILState_Release");
    LOOKUP(GILState_GetThisThreadState, "PyGILState_GetThisThreadState");
    LOOKUP(Eval_SaveThread, "PyEval_SaveThread");
    LOOKUP(Eval_RestoreThread, "PyEval_RestoreThread");
    LOOKUP(IsFinalizing, "Py_IsFinalizing");
    if (!py.IsFinalizing) LOOKUP(IsFinalizing, "_Py_IsFinalizing");
    LOOKUP(ThreadState_Clear, "PyThreadState_Clear");
    LOOKUP(ThreadState_DeleteCurrent, "PyThreadState_DeleteCurrent");
    LOOKUP(Import_ImportModule, "PyImport_ImportModule");
    LOOKUP(Object_GetAttrString, "PyObject_GetAttrString");
    LOOKUP(Unicode_FromString, "PyUnicode_FromString");
    LOOKUP(List_Size, "PyList_Size");
    LOOKUP(List_GetItem, "PyList_GetItem");
    LOOKUP(Object_RichCompareBool, "PyObject_RichCompareBool");
    LOOKUP(Sequence_DelItem, "PySequence_DelItem");
    LOOKUP(Object_DelItem, "PyObject_DelItem");
    LOOKUP(Err_Clear, "PyErr_Clear");
    LOOKUP(DecRef, "Py_DecRef");
    LOOKUP(Object_Vectorcall, "PyObject_Vectorcall"); /* exported by 3.11-3.13 (checked) */
    if (!py.Object_Vectorcall) LOOKUP(Object_Vectorcall, "PyObject_VectorcallDict"); /* else */
    LOOKUP(Float_FromDouble, "PyFloat_FromDouble");
    LOOKUP(Long_FromLong, "PyLong_FromLong");
    LOOKUP(Bool_FromLong, "PyBool_FromLong");
    LOOKUP(Float_AsDouble, "PyFloat_AsDouble");
    LOOKUP(Tuple_Size, "PyTuple_Size");
    LOOKUP(Tuple_GetItem, "PyTuple_GetItem");
    LOOKUP(Err_Occurred, "PyErr_Occurred");
    LOOKUP(None, "_Py_NoneStruct");
    LOOKUP(Object_IsTrue, "PyObject_IsTrue");
    LOOKUP(Err_Print, "PyErr_Print");
#undef LOOKUP
    char off[16];
    use_thread_state_keeper = !(environment("SMA_FMU_NO_TSTATE", off, sizeof off) &&
                                strcmp(off, "0") != 0);
    if (!thread_slot_create(release_kept_state)) use_thread_state_keeper = 0;
    calls->keep_thread_state = owner_keep_thread_state;
    calls->instantiate = owner_instantiate;
    calls->forget_resources = owner_forget_resources;
    calls->call_step = py.Object_Vectorcall && py.Float_FromDouble && py.Long_FromLong &&
                       py.Bool_FromLong && py.Float_AsDouble && py.Tuple_Size && py.Tuple_GetItem &&
                       py.Err_Occurred && py.None && py.Object_IsTrue && py.Err_Print &&
                       py.List_Size && py.Err_Clear && py.DecRef && py.GILState_Release
                       ? owner_call_step : NULL;
    return py.IsInitialized && py.GILState_Ensure && py.GILState_GetThisThreadState &&
           py.Eval_SaveThread && py.Eval_RestoreThread;
}
