/*
 * limber._fast: the state copy of a control loop, called without ctypes.
 *
 * A CPython extension that pip builds into the wheel (python/_build/limber_build.py) when a
 * C compiler and Python's headers are there; without it the package calls the same function
 * through ctypes (limber/_lib.py, `copy_out`). It holds no rule of its own: it calls the
 * liblimber function it is given, by address, with a new instance of the struct type it is
 * given, and returns the instance or the function's code. liblimber decides everything (what
 * a state is, the timeout, the checks); the Python client maps the code to its exception.
 *
 * Why: ctypes prepares every call anew (argument conversion, libffi), which costs a state read
 * more than liblimber's own work. Measured on this project's VM (CPython 3.11, a state of
 * 1336 B read right after a command's round trip): 2.4 us through ctypes, 1.5 us through this.
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
             "copy_out(fn, handle, timeout_ms, cls) -> cls instance | int\n\n"
             "Calls the liblimber function at address `fn` (shape of limber_device_state) "
             "with `handle` (an address, 0 for none), `timeout_ms` and a new instance of the "
             "ctypes struct type `cls` (its size as the size): the instance when the call "
             "returns 0, else the code it returned. The GIL is released while it waits "
             "(timeout_ms > 0).");

static PyObject *copy_out(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "copy_out(fn, handle, timeout_ms, cls) takes 4 arguments");
        return NULL;
    }
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
    PyObject *out = PyObject_CallNoArgs(args[3]);
    if (out == NULL) {
        return NULL;
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
