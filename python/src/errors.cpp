// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/errors.cpp — lumx's located diagnostics in Python: lumx.Finding, lumx.Error (a ValueError),
// OSError for failed I/O, lumx.LumxWarning through the warnings module; plus the array helpers.
#include "common.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <exception>
#include <stdexcept>

namespace lumx_py {

namespace {

// Created once at import and never destroyed: the interpreter owns them, and tearing them down in a
// static destructor after the interpreter has gone would crash.
PyObject* g_error = nullptr;
PyObject* g_warning = nullptr;

py::object optional_line(const lumx::Diagnostic& d) {
  return d.line > 0 ? py::object(py::int_(d.line)) : py::none();
}
py::object optional_offset(const lumx::Diagnostic& d) {
  return d.byte_offset >= 0 ? py::object(py::int_(d.byte_offset)) : py::none();
}

// Copies a finding's fields onto an exception or warning instance, so `except lumx.Error as e: e.line`
// works without parsing the text.
void attach_fields(py::handle target, const lumx::Diagnostic& d) {
  target.attr("file") = d.file;
  target.attr("line") = optional_line(d);
  target.attr("byte_offset") = optional_offset(d);
  target.attr("field") = d.field;
  target.attr("message") = d.message;
  target.attr("severity") = lumx::to_string(d.severity);
  target.attr("finding") = to_python(d);
}

// lumx's I/O failures end in ": " + strerror(errno) (io/atomic_file.cpp, rays/rayset_common.cpp,
// bundle/bundle_io.cpp); that suffix gives the errno back. 0: not an I/O failure.
int io_errno(const lumx::Diagnostic& d) {
  static const int candidates[] = {ENOENT, EACCES,       EPERM,     EISDIR, ENOTDIR, ENOSPC, EIO,
                                   EROFS,  EEXIST,       ENOTEMPTY, EXDEV,  EMFILE,  ENFILE, ELOOP,
                                   EBUSY,  ENAMETOOLONG, EDQUOT,    EFBIG,  EINVAL};
  for (int e : candidates) {
    const std::string suffix = std::string(": ") + std::strerror(e);
    const std::string& m = d.message;
    if (m.size() >= suffix.size() && m.compare(m.size() - suffix.size(), suffix.size(), suffix) == 0) return e;
    if (m == std::strerror(e)) return e;
  }
  if (d.field == "bundle" && d.message == "does not exist") return ENOENT;
  if (d.field == "bundle" && d.message == "is not a folder") return ENOTDIR;
  return 0;
}

void raise_error(const lumx::Diagnostic& d) {
  if (const int e = io_errno(d)) {
    // OSError(errno, strerror, filename) becomes FileNotFoundError, PermissionError, ... by itself.
    py::object error = py::reinterpret_borrow<py::object>(PyExc_OSError)(e, d.str(), d.file);
    attach_fields(error, d);
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
    return;
  }
  py::object error = py::reinterpret_borrow<py::object>(g_error)(d.str());
  attach_fields(error, d);
  PyErr_SetObject(g_error, error.ptr());
}

}  // namespace

py::object to_python(const lumx::Diagnostic& d) {
  return py::cast(d);
}

void WarningCollector::emit(int stacklevel) {
  std::vector<lumx::Diagnostic> items;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    items.swap(items_);
  }
  if (items.empty()) return;
  py::object warn = py::module_::import("warnings").attr("warn");
  for (const lumx::Diagnostic& d : items) {
    py::object w = py::reinterpret_borrow<py::object>(g_warning)(d.str());
    attach_fields(w, d);
    warn(w, py::arg("stacklevel") = stacklevel);
  }
}

void ProgressCallback::operator()(double fraction, const char* phase) {
  if (callback_.is_none()) return;
  fraction = std::max(fraction, last_);
  last_ = fraction;
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  callback_(fraction, phase);
}

Vec3Rows vec3_rows(const py::handle& value, const char* what) {
  Vec3Rows r;
  r.array = DoubleArray::ensure(value);
  if (!r.array) {
    PyErr_Clear();
    throw py::value_error(std::string(what) + ": expected an (N, 3) array of numbers");
  }
  if (r.array.ndim() == 1 && r.array.shape(0) == 3) {
    r.single = true;
    r.count = 1;
  } else if (r.array.ndim() == 2 && r.array.shape(1) == 3) {
    r.count = std::size_t(r.array.shape(0));
  } else {
    throw py::value_error(std::string(what) + ": expected shape (N, 3) or (3,), got " +
                          std::string(py::str(py::tuple(
                              py::cast(std::vector<py::ssize_t>(r.array.shape(), r.array.shape() + r.array.ndim()))))));
  }
  return r;
}

DoubleArray vector_of(const py::handle& value, std::size_t count, const char* what) {
  DoubleArray a = DoubleArray::ensure(value);
  if (!a) {
    PyErr_Clear();
    throw py::value_error(std::string(what) + ": expected an array of numbers");
  }
  if (a.ndim() == 0 && count == 1) return DoubleArray::ensure(a.reshape({py::ssize_t(1)}));
  if (a.ndim() != 1 || std::size_t(a.shape(0)) != count)
    throw py::value_error(std::string(what) + ": expected " + std::to_string(count) + " values (shape (" +
                          std::to_string(count) + ",))");
  return a;
}

py::object scalar_or_array(py::array_t<double> values, bool single) {
  if (single) return py::float_(values.at(0));
  return std::move(values);
}

void bind_errors(py::module_& m) {
  py::class_<lumx::Diagnostic>(m, "Finding",
                               "One located finding of a check or reader: where (file, line or byte offset), "
                               "which field, what, and how bad.")
      .def_property_readonly(
          "severity", [](const lumx::Diagnostic& d) { return lumx::to_string(d.severity); },
          "'error', 'warning' or 'note'")
      .def_readonly("file", &lumx::Diagnostic::file, "the file (or bundle folder) the finding is about")
      .def_property_readonly("line", optional_line, "1-based line of a text file, or None")
      .def_property_readonly("byte_offset", optional_offset, "byte offset in a binary file, or None")
      .def_readonly("field", &lumx::Diagnostic::field, "the file-format field, e.g. 'vertical angle count'")
      .def_readonly("message", &lumx::Diagnostic::message, "what is wrong")
      .def("__str__", &lumx::Diagnostic::str)
      .def("__repr__", [](const lumx::Diagnostic& d) { return "<lumx.Finding " + d.str() + ">"; });

  g_error = PyErr_NewExceptionWithDoc(
      "lumx.Error",
      "Bad input: a file, bundle or value lumx cannot accept. A ValueError whose attributes locate it: "
      "file, line (or None), byte_offset (or None), field, message, severity and finding (a lumx.Finding). "
      "Failed I/O raises OSError (FileNotFoundError, PermissionError, ...) with the same attributes.",
      PyExc_ValueError, nullptr);
  if (!g_error) throw py::error_already_set();
  m.attr("Error") = py::handle(g_error);
  g_warning = PyErr_NewExceptionWithDoc(
      "lumx.LumxWarning",
      "A reader's warning (data accepted, but not as the standard says), issued through the warnings "
      "module with the attributes of lumx.Error.",
      PyExc_UserWarning, nullptr);
  if (!g_warning) throw py::error_already_set();
  m.attr("LumxWarning") = py::handle(g_warning);

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const lumx::Error& e) {
      raise_error(e.diagnostic());
    }
  });
}

}  // namespace lumx_py
