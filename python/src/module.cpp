// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/module.cpp — the extension lumx._lumx; the package lumx (python/lumx/__init__.py) re-exports it.
#include "common.h"

#include <lumx/version.h>

PYBIND11_MODULE(_lumx, m) {
  m.doc() = "lumx: luminaire photometry, raysets and APL bundles (the C++ core, bound with pybind11)";
  m.attr("__version__") = lumx::kLibraryVersion;
  m.attr("abi_namespace") = lumx::kAbiNamespace;
  lumx_py::bind_errors(m);
  lumx_py::bind_photometry(m);
  lumx_py::bind_rays(m);
  lumx_py::bind_bundle(m);
  lumx_py::bind_build(m);
  lumx_py::bind_bake(m);
}
