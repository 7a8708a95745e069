// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/common.h — what every part of the extension shares: NumPy argument checks, located
// warnings turned into Python warnings, and the exception mapping (errors.cpp).
#pragma once

#include <lumx/core/diagnostic.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <glm/glm.hpp>

#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

namespace lumx_py {

namespace py = pybind11;

/// A C-contiguous float64 array, converted from whatever the caller passed (lists, float32, views).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// Rows of an (N, 3) array, or of a single (3,) vector (then `single` is set); throws ValueError naming
/// `what` for any other shape.
struct Vec3Rows {
  DoubleArray array;
  std::size_t count = 0;
  bool single = false;
  glm::dvec3 at(std::size_t i) const {
    const double* p = array.data() + 3 * i;
    return {p[0], p[1], p[2]};
  }
};
Vec3Rows vec3_rows(const py::handle& value, const char* what);

/// An (N,) array of float64 with N = `count` (or a scalar when count == 1 and the rows were single).
DoubleArray vector_of(const py::handle& value, std::size_t count, const char* what);

/// A result of shape (N,) — or a Python float when the input was a single vector.
py::object scalar_or_array(py::array_t<double> values, bool single);

/// Collects the warnings C++ reports while the GIL is released; emit() turns each into a Python
/// warning (category lumx.LumxWarning, carrying the finding) once the GIL is held again.
class WarningCollector {
 public:
  lumx::DiagnosticSink sink() {
    return [this](const lumx::Diagnostic& d) {
      std::lock_guard<std::mutex> lock(mutex_);
      items_.push_back(d);
    };
  }
  /// Raises the Python warnings (which may themselves raise, under -W error).
  void emit(int stacklevel = 1);

 private:
  std::mutex mutex_;
  std::vector<lumx::Diagnostic> items_;
};

/// Registers lumx.Error, lumx.LumxWarning, lumx.Finding and the exception translator (errors.cpp).
void bind_errors(py::module_& m);
/// The Python object for a finding (a lumx.Finding).
py::object to_python(const lumx::Diagnostic& d);

void bind_photometry(py::module_& m);
void bind_rays(py::module_& m);
void bind_bundle(py::module_& m);
void bind_build(py::module_& m);
void bind_bake(py::module_& m);

/// Calls a Python progress callable from C++ work running without the GIL: takes the GIL, calls
/// `callback(fraction, phase)`, and lets an exception in it (including KeyboardInterrupt, checked on
/// every call) stop the work by throwing it through the C++ code as py::error_already_set. The fraction
/// passed on never decreases, though stages of the work may start their own counts again.
class ProgressCallback {
 public:
  explicit ProgressCallback(py::object callback) : callback_(std::move(callback)) {}
  bool empty() const { return callback_.is_none(); }
  void operator()(double fraction, const char* phase);

 private:
  py::object callback_;
  double last_ = 0;
};

}  // namespace lumx_py
