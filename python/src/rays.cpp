// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/rays.cpp — raysets: lumx.open_rays (a streamed RayFile yielding structured-array chunks),
// lumx.RaysetInfo, lumx.write_tm25.
#include "rays.h"

#include <cmath>
#include <cstring>
#include <optional>

namespace lumx_py {

namespace {

constexpr std::size_t kRecord = 7 * sizeof(float);  // position, direction, flux

lumx::FluxPreference flux_preference(const std::string& s) {
  if (s == "auto") return lumx::FluxPreference::automatic;
  if (s == "luminous") return lumx::FluxPreference::luminous;
  if (s == "radiant") return lumx::FluxPreference::radiant;
  throw py::value_error("flux: expected 'auto', 'luminous' or 'radiant', got '" + s + "'");
}

lumx::RaysetFormat format_from(const std::string& s) {
  for (lumx::RaysetFormat f :
       {lumx::RaysetFormat::tm25, lumx::RaysetFormat::lighttools_binary, lumx::RaysetFormat::lighttools_text,
        lumx::RaysetFormat::zemax_binary, lumx::RaysetFormat::zemax_text, lumx::RaysetFormat::plain_text})
    if (s == lumx::to_string(f)) return f;
  throw py::value_error(
      "format: expected one of 'TM-25', 'LightTools binary', 'LightTools text', 'Zemax binary', "
      "'Zemax text', 'plain text'; got '" +
      s + "'");
}

lumx::PhotometricQuantity quantity_from(const std::string& s) {
  if (s == "photometric") return lumx::PhotometricQuantity::photometric;
  if (s == "radiometric") return lumx::PhotometricQuantity::radiometric;
  throw py::value_error("quantity: expected 'photometric' (lm) or 'radiometric' (W), got '" + s + "'");
}

const char* quantity_name(lumx::PhotometricQuantity q) {
  return q == lumx::PhotometricQuantity::photometric ? "photometric" : "radiometric";
}

// Column `name` of a structured array or mapping as a C-contiguous float32 array, or nullopt if absent.
std::optional<FloatArray> column(const py::handle& value, const char* name) {
  py::object col;
  if (py::isinstance<py::array>(value)) {
    py::array a = py::reinterpret_borrow<py::array>(value);
    py::object names = a.dtype().attr("names");
    if (names.is_none())
      throw py::value_error("rays: expected a structured array with fields position, direction, flux");
    bool found = false;
    for (auto n : names) found = found || n.cast<std::string>() == name;
    if (!found) return std::nullopt;
    col = a[py::str(name)];
  } else {
    py::object mapping = py::reinterpret_borrow<py::object>(value);
    if (!py::hasattr(mapping, "__contains__") || !py::hasattr(mapping, "__getitem__"))
      throw py::value_error("rays: expected a structured array or a mapping with position, direction and flux");
    if (!mapping.attr("__contains__")(name).cast<bool>()) return std::nullopt;
    col = mapping[py::str(name)];
  }
  FloatArray f = FloatArray::ensure(col);
  if (!f) {
    PyErr_Clear();
    throw py::value_error(std::string("rays: ") + name + " is not an array of numbers");
  }
  return f;
}

void fill(std::vector<float>& out, const float* p, std::size_t n, std::size_t stride) {
  out.resize(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = p[i * stride];
}

}  // namespace

py::dtype ray_dtype(bool wavelength) {
  py::list fields;
  fields.append(py::make_tuple("position", "<f4", py::make_tuple(3)));
  fields.append(py::make_tuple("direction", "<f4", py::make_tuple(3)));
  fields.append(py::make_tuple("flux", "<f4"));
  if (wavelength) fields.append(py::make_tuple("wavelength_nm", "<f4"));
  return py::dtype::from_args(fields);
}

py::array chunk_to_array(const lumx::RayChunk& c) {
  const bool wl = !c.wavelength_nm.empty();
  py::array out(ray_dtype(wl), std::vector<py::ssize_t>{py::ssize_t(c.size())});
  char* base = static_cast<char*>(out.mutable_data());
  const std::size_t record = kRecord + (wl ? sizeof(float) : 0);
  for (std::size_t i = 0; i < c.size(); ++i) {
    const float v[8] = {c.x[i], c.y[i], c.z[i], c.dx[i], c.dy[i], c.dz[i], c.flux[i], wl ? c.wavelength_nm[i] : 0.0f};
    std::memcpy(base + i * record, v, record);
  }
  return out;
}

lumx::RayChunk chunk_from_python(const py::handle& value) {
  const std::optional<FloatArray> p = column(value, "position"), d = column(value, "direction"),
                                  f = column(value, "flux"), w = column(value, "wavelength_nm");
  if (!p || !d || !f) throw py::value_error("rays: position, direction and flux are all needed");
  const FloatArray &pos = *p, &dir = *d, &flux = *f;
  const FloatArray* wl = w ? &*w : nullptr;
  const std::size_t n = std::size_t(flux.size());
  if (flux.ndim() != 1) throw py::value_error("rays: flux must have shape (N,)");
  for (const FloatArray* a : {&pos, &dir})
    if (a->ndim() != 2 || a->shape(1) != 3 || std::size_t(a->shape(0)) != n)
      throw py::value_error("rays: position and direction must have shape (N, 3), N = len(flux)");
  if (wl && (wl->ndim() != 1 || std::size_t(wl->shape(0)) != n))
    throw py::value_error("rays: wavelength_nm must have shape (N,)");
  lumx::RayChunk c;
  fill(c.x, pos.data(), n, 3), fill(c.y, pos.data() + 1, n, 3), fill(c.z, pos.data() + 2, n, 3);
  fill(c.dx, dir.data(), n, 3), fill(c.dy, dir.data() + 1, n, 3), fill(c.dz, dir.data() + 2, n, 3);
  fill(c.flux, flux.data(), n, 1);
  if (wl) fill(c.wavelength_nm, wl->data(), n, 1);
  return c;
}

// ---- RayFile

RayFile::RayFile(const std::string& path, std::size_t chunk_rays, const std::string& flux, const py::object& format)
    : chunk_rays_(chunk_rays) {
  if (chunk_rays < 1) throw py::value_error("chunk_rays must be at least 1");
  lumx::RaysetReadOptions o;
  o.chunk_rays = chunk_rays;
  o.flux = flux_preference(flux);
  if (!format.is_none()) o.format = format_from(format.cast<std::string>());
  o.warnings = warnings_.sink();
  {
    py::gil_scoped_release release;
    source_ = lumx::open_rayset(path, o);
  }
  warnings_.emit(1);
}

lumx::RaySource& RayFile::source() {
  if (!source_) throw py::value_error("the ray file is closed");
  return *source_;
}

const lumx::RaysetInfo& RayFile::info() const {
  if (!source_) throw py::value_error("the ray file is closed");
  return source_->info();
}

py::object RayFile::next_chunk() {
  lumx::RayChunk chunk;
  bool more = false;
  {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    more = source().next(chunk, chunk_rays_);
  }
  warnings_.emit(1);
  if (!more) return py::none();
  return chunk_to_array(chunk);
}

void RayFile::rewind() {
  py::gil_scoped_release release;
  std::lock_guard<std::mutex> lock(mutex_);
  source().rewind();
}

void RayFile::close() {
  std::lock_guard<std::mutex> lock(mutex_);
  source_.reset();
}

// ---- PythonRaySource

PythonRaySource::PythonRaySource(py::object rays, lumx::RaysetInfo info) : info_(std::move(info)) {
  if (PyCallable_Check(rays.ptr()))
    factory_ = std::move(rays);
  else
    iterable_ = std::move(rays);
}

PythonRaySource::~PythonRaySource() {
  // The Python references may be dropped on a thread without the GIL.
  py::gil_scoped_acquire gil;
  iterator_ = py::object();
  iterable_ = py::object();
  factory_ = py::object();
}

void PythonRaySource::rewind() {
  py::gil_scoped_acquire gil;
  pending_.clear();
  pending_at_ = 0;
  if (factory_) {
    iterator_ = py::iter(factory_());
  } else {
    if (started_)
      throw py::value_error(
          "rays: an iterable of chunks can be read only once; pass a callable that returns a new one for "
          "work that reads the rays more than once");
    iterator_ = py::iter(iterable_);
  }
  started_ = false;
}

bool PythonRaySource::next(lumx::RayChunk& out, std::size_t max_rays) {
  out.clear();
  max_rays = std::max<std::size_t>(1, max_rays);
  py::gil_scoped_acquire gil;
  if (!iterator_) {
    iterator_ = factory_ ? py::iter(factory_()) : py::iter(iterable_);
  }
  started_ = true;
  while (pending_at_ >= pending_.size()) {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    py::handle item = PyIter_Next(iterator_.ptr());
    if (!item) {
      if (PyErr_Occurred()) throw py::error_already_set();
      return false;
    }
    py::object owned = py::reinterpret_steal<py::object>(item);
    pending_ = chunk_from_python(owned);
    pending_at_ = 0;
  }
  const std::size_t end = std::min(pending_.size(), pending_at_ + max_rays);
  auto take = [&](const std::vector<float>& from, std::vector<float>& to) {
    if (!from.empty()) to.assign(from.begin() + std::ptrdiff_t(pending_at_), from.begin() + std::ptrdiff_t(end));
  };
  take(pending_.x, out.x), take(pending_.y, out.y), take(pending_.z, out.z);
  take(pending_.dx, out.dx), take(pending_.dy, out.dy), take(pending_.dz, out.dz);
  take(pending_.flux, out.flux), take(pending_.wavelength_nm, out.wavelength_nm);
  pending_at_ = end;
  return true;
}

lumx::RaySource& rays_argument(const py::object& rays, std::unique_ptr<lumx::RaySource>& holder,
                               std::unique_lock<std::mutex>& file_lock, WarningCollector& warnings) {
  if (py::isinstance<RayFile>(rays)) {
    RayFile& f = rays.cast<RayFile&>();
    file_lock = std::unique_lock<std::mutex>(f.mutex());
    return f.source();
  }
  if (py::isinstance<py::str>(rays) || py::hasattr(rays, "__fspath__")) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(rays));
    lumx::RaysetReadOptions o;
    o.warnings = warnings.sink();
    py::gil_scoped_release release;
    holder = lumx::open_rayset(path, o);
    return *holder;
  }
  lumx::RaysetInfo info;
  info.file = "<python>";
  info.format = "arrays";
  if (py::isinstance<py::array>(rays) || py::isinstance<py::dict>(rays)) {
    lumx::RayChunk chunk = chunk_from_python(rays);
    holder = std::make_unique<lumx::MemoryRaySource>(std::move(chunk), std::move(info));
    return *holder;
  }
  holder = std::make_unique<PythonRaySource>(rays, std::move(info));
  return *holder;
}

// ---- bindings

void bind_rays(py::module_& m) {
  py::class_<lumx::RaysetInfo>(m, "RaysetInfo", "What a rayset's header says. Lengths in m after reading.")
      .def_readonly("file", &lumx::RaysetInfo::file)
      .def_readonly("format", &lumx::RaysetInfo::format, "'TM-25', 'LightTools binary', ... ")
      .def_readonly("version", &lumx::RaysetInfo::version)
      .def_readonly("ray_count", &lumx::RaysetInfo::ray_count, "rays in the file")
      .def_property_readonly(
          "quantity", [](const lumx::RaysetInfo& i) { return quantity_name(i.quantity); },
          "'photometric' (flux in lm) or 'radiometric' (W)")
      .def_property_readonly(
          "flux_unit", [](const lumx::RaysetInfo& i) { return lumx::flux_unit(i.quantity); }, "'lm' or 'W'")
      .def_property_readonly(
          "header_flux",
          [](const lumx::RaysetInfo& i) {
            return std::isnan(i.header_flux) ? py::object(py::none()) : py::object(py::float_(i.header_flux));
          },
          "total flux the header states (lm or W), or None; never applied to the rays")
      .def_readonly("source_length_unit", &lumx::RaysetInfo::source_length_unit,
                    "the file's length unit before conversion to metres")
      .def_readonly("wavelength_nm", &lumx::RaysetInfo::wavelength_nm, "single wavelength, nm, or None")
      .def_property_readonly(
          "spectra",
          [](const lumx::RaysetInfo& i) {
            py::list out;
            for (const auto& t : i.spectra)
              out.append(py::make_tuple(py::array_t<float>(py::ssize_t(t.wavelength_nm.size()), t.wavelength_nm.data()),
                                        py::array_t<float>(py::ssize_t(t.weight.size()), t.weight.data())));
            return out;
          },
          "spectral tables as (wavelength_nm, weight) array pairs")
      .def_readonly("text", &lumx::RaysetInfo::text, "named text fields")
      .def_readonly("values", &lumx::RaysetInfo::values, "other numeric header fields by name")
      .def_readonly("simulated", &lumx::RaysetInfo::simulated)
      .def("__repr__", [](const lumx::RaysetInfo& i) {
        return "<lumx.RaysetInfo " + i.format + ", " + std::to_string(i.ray_count) + " rays, '" + i.file + "'>";
      });

  py::class_<RayFile>(
      m, "RayFile",
      "An open rayset (IES TM-25, LightTools, Zemax, plain text). Iterating yields chunks of at "
      "most chunk_rays rays as NumPy structured arrays with fields position (3,) m, direction "
      "(3,) unit, flux (lm or W per ray), and wavelength_nm when the file has one per ray; the "
      "file is read through a bounded window, never whole. Each `for` loop starts again from the first ray.")
      .def_property_readonly("info", &RayFile::info, py::return_value_policy::copy,
                             "the header (lumx.RaysetInfo; a copy, valid after close())")
      .def_property_readonly("chunk_rays", &RayFile::chunk_rays)
      .def("next_chunk", &RayFile::next_chunk, "The next chunk (structured array), or None after the last ray.")
      .def("rewind", &RayFile::rewind, "Start again from the first ray.")
      .def("close", &RayFile::close, "Release the file.")
      .def("__iter__",
           [](py::object self) {
             self.cast<RayFile&>().rewind();
             return self;
           })
      .def("__next__",
           [](RayFile& f) {
             py::object c = f.next_chunk();
             if (c.is_none()) throw py::stop_iteration();
             return c;
           })
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](RayFile& f, const py::args&) { f.close(); })
      .def(
          "summary",
          [](RayFile& f) {
            lumx::RaysetSummary s;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(f.mutex());
              s = lumx::summarize_rays(f.source(), f.chunk_rays());
            }
            py::dict d;
            d["rays"] = s.rays;
            d["flux_sum"] = s.flux_sum;
            d["lo"] = py::make_tuple(s.lo.x, s.lo.y, s.lo.z);
            d["hi"] = py::make_tuple(s.hi.x, s.hi.y, s.hi.z);
            d["center"] = py::make_tuple(s.bounds.center.x, s.bounds.center.y, s.bounds.center.z);
            d["radius"] = s.bounds.radius;
            d["zero_flux_rays"] = s.zero_flux_rays;
            return d;
          },
          "Streams every ray once: rays, flux_sum (lm or W), the start points' box lo/hi (m), its centre and "
          "the radius to the farthest start point (m), zero_flux_rays. Leaves the file at its end.")
      .def(
          "read_all",
          [](RayFile& f, std::uint64_t max_rays) {
            lumx::RayChunk all;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(f.mutex());
              all = lumx::read_all_rays(f.source(), max_rays);
            }
            return chunk_to_array(all);
          },
          py::arg("max_rays"),
          "Every ray in one structured array; raises lumx.Error when the file holds more than max_rays, so "
          "the caller states the memory it accepts (28 bytes per ray).");

  m.def("ray_dtype", &ray_dtype, py::arg("wavelength") = false,
        "The structured dtype of ray chunks: position (3,) m, direction (3,), flux (lm or W), float32 each, "
        "plus wavelength_nm (nm) when asked.");

  m.def(
      "open_rays",
      [](const std::string& path, std::size_t chunk_rays, const std::string& flux, const py::object& format) {
        return std::make_unique<RayFile>(path, chunk_rays, flux, format);
      },
      py::arg("path"), py::arg("chunk_rays") = 65536, py::arg("flux") = "auto", py::arg("format") = py::none(),
      "Opens a rayset and reads its header (checked against the file size). `flux`: for TM-25 files with "
      "both columns, 'auto' (luminous), 'luminous' or 'radiant'. `format` forces a reader ('TM-25', ...). "
      "Raises lumx.Error (located at a byte offset or line) or OSError.");

  m.def(
      "write_tm25",
      [](const std::string& path, const py::object& rays, const py::object& quantity, const py::object& header_flux,
         const std::map<std::string, std::string>& text, const py::object& wavelength_nm, std::size_t chunk_rays) {
        WarningCollector warnings;
        std::unique_ptr<lumx::RaySource> holder;
        std::unique_lock<std::mutex> file_lock;
        lumx::RaySource& source = rays_argument(rays, holder, file_lock, warnings);
        lumx::RaysetInfo info = source.info();
        const bool from_file =
            py::isinstance<RayFile>(rays) || py::isinstance<py::str>(rays) || py::hasattr(rays, "__fspath__");
        if (!from_file) info = lumx::RaysetInfo{};
        if (!quantity.is_none()) info.quantity = quantity_from(quantity.cast<std::string>());
        lumx::Tm25WriteOptions o;
        o.chunk_rays = chunk_rays;
        if (!header_flux.is_none()) {
          info.header_flux = header_flux.cast<double>();
        } else if (!from_file) {
          o.header_flux_from_rays = true;
        }
        for (const auto& [k, v] : text) info.text[k] = v;
        if (!wavelength_nm.is_none()) info.wavelength_nm = wavelength_nm.cast<double>();
        {
          py::gil_scoped_release release;
          lumx::write_tm25(path, info, source, o);
        }
        warnings.emit();
        if (py::isinstance<RayFile>(rays)) rays.cast<RayFile&>().emit_warnings();
      },
      py::arg("path"), py::arg("rays"), py::arg("quantity") = py::none(), py::arg("header_flux") = py::none(),
      py::arg("text") = std::map<std::string, std::string>{}, py::arg("wavelength_nm") = py::none(),
      py::arg("chunk_rays") = 65536,
      "Writes rays as an IES TM-25 file, atomically, streaming: `rays` is a path or lumx.RayFile (converted, "
      "its header kept), a structured array or mapping (position (N, 3) m, direction (N, 3), flux (N,) lm or "
      "W), an iterable of such chunks (read once), or a callable returning one. `quantity`: 'photometric' "
      "(default) or 'radiometric'. `header_flux` (lm or W) defaults to the sum of the rays written. `text`: "
      "TM-25 text fields by name: name, manufacturer, model creator, ray file creator, equipment, camera, "
      "operating condition, additional information, data reference.");
}

}  // namespace lumx_py
