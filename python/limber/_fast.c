/*
 * limber._fast: the state copy of a control loop, called without ctypes.
 *
 * A CPython extension that pip builds into the wheel (python/_build/limber_build.py) when a
 * C compiler and Python's headers are there; without it the package calls the same function
 * through ctypes (limber/_lib.py, `copy_out`). It holds no rule of its own: it calls the
 * liblimber function it is given, by address, with an instance of the struct type it is given
 * (new, or one it recycles: `take_spare`), and returns the instance or the function's code.
 * liblimber decides everything (what a state is, the timeout, the checks); the Python client
 * maps the code to its exception.
 *
 * Why: ctypes prepares every call anew (argument conversion, libffi), which costs a state read
 * more than liblimber's own work, and so does allocating the state. Measured on this project's
 * VM (CPython 3.11, `limber bench --only lang`: a state of 1376 B read right after a command's
 * round trip): 1.6-2.4 us through ctypes, 0.84-0.88 us through this (1.0 us without recycling).
 *
 * It does not link liblimber: the address comes from the library ctypes loaded, so both paths
 * use one library and one handle.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>

/* The shape of `limber_device_state` and `limber_device_wait_state`. */
typedef int32_t (*limber_copy_fn)(void *handle, uint64_t timeout_ms, void *out, size_t size);

PyDoc_STRVAR(copy_out_doc,
             "copy_out(fn, handle, timeout_ms, cls, spare=None) -> cls instance | int\n\n"
             "Calls the liblimber function at address `fn` (shape of limber_device_state) "
             "with `handle` (an address, 0 for none), `timeout_ms` and an instance of the "
             "ctypes struct type `cls` (its size as the size): the instance when the call "
             "returns 0, else the code it returned. The GIL is released while it waits "
             "(timeout_ms > 0).\n\n"
             "The instance is new, or, with `spare` (a list the caller keeps, two entries), "
             "one that an earlier call returned and that nothing but `spare` holds any more "
             "(`cls` without an instance dict or weak references: __slots__ = ()). Nobody can "
             "tell it from a new one; it saves an allocation of the state (~0.15 us of a "
             "read in a control loop).");

/*
 * An instance of `cls` in `spare` that nothing else holds (its only reference is the list's),
 * with a new reference for the caller; NULL if there is none. Only for a type whose instances
 * carry no dict and no weak references (ctypes' own struct has both; `__slots__ = ()` removes
 * them): otherwise an attribute set on, or a weak reference to, a state dropped long ago would
 * show on a new one. With the GIL held: a reference count of 1 is then the whole truth, and the
 * caller's new reference keeps another thread from taking the same instance while this one
 * waits without the GIL.
 */
static PyObject *take_spare(PyObject *spare, PyObject *cls) {
    if (!PyType_Check(cls)) {
        return NULL;
    }
    PyTypeObject *type = (PyTypeObject *)cls;
    if (type->tp_dictoffset != 0 || type->tp_weaklistoffset != 0) {
        return NULL;
    }
    for (Py_ssize_t i = 0; i < 2; i++) {
        PyObject *o = PyList_GET_ITEM(spare, i);
        if (Py_IS_TYPE(o, type) && Py_REFCNT(o) == 1) {
            Py_INCREF(o);
            return o;
        }
    }
    return NULL;
}

/*
 * Keeps `out` (new) in `spare` in place of the older entry: the two newest instances stay,
 * so that a loop holding its last state (`s = client.state()`) finds the other one free.
 */
static void keep_spare(PyObject *spare, PyObject *out) {
    PyObject *older = PyList_GET_ITEM(spare, 0);
    PyList_SET_ITEM(spare, 0, PyList_GET_ITEM(spare, 1));
    Py_INCREF(out);
    PyList_SET_ITEM(spare, 1, out);
    Py_XDECREF(older);
}

static PyObject *copy_out(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 4 && nargs != 5) {
        PyErr_SetString(PyExc_TypeError,
                        "copy_out(fn, handle, timeout_ms, cls, spare=None) takes 4 or 5 arguments");
        return NULL;
    }
    PyObject *spare = nargs == 5 && args[4] != Py_None ? args[4] : NULL;
    if (spare != NULL && (!PyList_CheckExact(spare) || PyList_GET_SIZE(spare) != 2)) {
        PyErr_SetString(PyExc_TypeError, "copy_out: spare is a list of two entries, or None");
        return NULL;
    }
#ifdef Py_GIL_DISABLED
    /* Free-threaded CPython: a reference count read here is not the whole truth, and the
     * list is not ours alone while we change it. Every instance is new. */
    spare = NULL;
#endif
    void *fn_addr = PyLong_AsVoidPtr(args[0]);
    if (fn_addr == NULL) {
        if (!PyErr_Occurred()) {
            PyErr_SetString(PyExc_ValueError, "copy_out: fn is the address of a liblimber function, not 0");
        }
        return NULL;
    }
    void *handle = NULL;
    if (args[1] != Py_None) {
        handle = PyLong_AsVoidPtr(args[1]);
        if (handle == NULL && PyErr_Occurred()) {
            return NULL;
        }
    }
    unsigned long long timeout_ms = PyLong_AsUnsignedLongLong(args[2]);
    if (timeout_ms == (unsigned long long)-1 && PyErr_Occurred()) {
        return NULL;
    }
    PyObject *out = spare != NULL ? take_spare(spare, args[3]) : NULL;
    if (out == NULL) {
        out = PyObject_CallNoArgs(args[3]);
        if (out == NULL) {
            return NULL;
        }
        if (spare != NULL) {
            keep_spare(spare, out);
        }
    }
    Py_buffer view;
    if (PyObject_GetBuffer(out, &view, PyBUF_WRITABLE) < 0) {
        Py_DECREF(out);
        return NULL;
    }
    /* A function pointer from an object pointer: POSIX guarantees the round trip (dlsym). */
    limber_copy_fn fn = (limber_copy_fn)(uintptr_t)fn_addr;
    int32_t code;
    if (timeout_ms == 0) {
        code = fn(handle, 0, view.buf, (size_t)view.len);
    } else {
        Py_BEGIN_ALLOW_THREADS
        code = fn(handle, (uint64_t)timeout_ms, view.buf, (size_t)view.len);
        Py_END_ALLOW_THREADS
    }
    PyBuffer_Release(&view);
    if (code != 0) {
        Py_DECREF(out);
        return PyLong_FromLong((long)code);
    }
    return out;
}

static PyMethodDef methods[] = {
    {"copy_out", (PyCFunction)(void (*)(void))copy_out, METH_FASTCALL, copy_out_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT,
    "limber._fast",
    "The state copy of a control loop, called without ctypes (see limber/_lib.py).",
    -1,
    methods,
    NULL,
    NULL,
    NULL,
    NULL,
};

PyMODINIT_FUNC PyInit__fast(void) { return PyModule_Create(&module); }
