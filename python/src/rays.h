// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/rays.h — raysets between C++ and Python: chunks as NumPy structured arrays, an open ray
// file, and rays that come from Python (arrays, iterables of chunks) as a lumx::RaySource.
#pragma once

#include "common.h"

#include <lumx/io/rayset_io.h>
#include <lumx/rays/rayset.h>

#include <memory>
#include <mutex>

namespace lumx_py {

/// The structured dtype of a chunk: position (3,) m, direction (3,) unit, flux (lm or W), all float32,
/// plus wavelength_nm when the file has one per ray.
py::dtype ray_dtype(bool wavelength);
/// A chunk as a structured array (one copy: C++ holds rays as structure of arrays).
py::array chunk_to_array(const lumx::RayChunk& chunk);
/// Rays from a structured array (fields position, direction, flux[, wavelength_nm]) or a mapping with those
/// keys ((N, 3), (N, 3), (N,) arrays); throws ValueError naming what is missing.
lumx::RayChunk chunk_from_python(const py::handle& value);

/// An open rayset (lumx.open_rays): the header read, rays streamed on request.
class RayFile {
 public:
  RayFile(const std::string& path, std::size_t chunk_rays, const std::string& flux, const py::object& format);
  const lumx::RaysetInfo& info() const;
  /// The next chunk as a structured array, or None at the end.
  py::object next_chunk();
  void rewind();
  void close();
  std::size_t chunk_rays() const { return chunk_rays_; }
  /// The source, for the builder and the TM-25 writer (GIL released by the caller; guarded by lock()).
  lumx::RaySource& source();
  std::mutex& mutex() { return mutex_; }
  /// Issues the warnings the reader gave so far (it gives some at the end of a pass, so they are
  /// collected for as long as the file is open).
  void emit_warnings() { warnings_.emit(1); }

 private:
  WarningCollector warnings_;  // before source_: the reader holds its sink
  std::unique_ptr<lumx::RaySource> source_;
  std::size_t chunk_rays_;
  std::mutex mutex_;
};

/// Rays supplied by Python: a callable returning an iterable of chunks (rewindable: called again on
/// rewind), or an iterable (readable once). Pulls chunks with the GIL taken, hands them out in pieces of
/// at most max_rays.
class PythonRaySource : public lumx::RaySource {
 public:
  PythonRaySource(py::object rays, lumx::RaysetInfo info);
  ~PythonRaySource() override;
  const lumx::RaysetInfo& info() const override { return info_; }
  bool next(lumx::RayChunk& out, std::size_t max_rays) override;
  void rewind() override;

 private:
  py::object factory_, iterable_, iterator_;
  lumx::RaysetInfo info_;
  lumx::RayChunk pending_;
  std::size_t pending_at_ = 0;
  bool started_ = false;
};

/// The source lumx.build and lumx.write_tm25 read: a path (opened here), a lumx.RayFile, arrays in memory
/// or Python chunks. `holder` keeps whatever was created alive; `file_lock` is set for a RayFile.
lumx::RaySource& rays_argument(const py::object& rays, std::unique_ptr<lumx::RaySource>& holder,
                               std::unique_lock<std::mutex>& file_lock, WarningCollector& warnings);

}  // namespace lumx_py
