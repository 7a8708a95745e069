// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/bundle.cpp — lumx bundles: lumx.Bundle (manifest only, levels loaded on request), lumx.Level
// (one loaded level: maps, irradiance, intensity, emission sampling, light choice), lumx.RadianceVolume.
//
// Each loaded level is its own immutable one-level AplSet with the bundle's metadata, shared between the
// Bundle's cache and the Level objects and map views handed out, so reloading a level never invalidates
// an array Python still holds. Per-point level choice (lod) picks levels on a skeleton set that has
// every level's APL count and error table but no maps, then evaluates each point on its level's set.
#include "common.h"

#include <lumx/apl/evaluation.h>
#include <lumx/apl/lod.h>
#include <lumx/apl/sampling.h>
#include <lumx/io/bundle_io.h>
#include <lumx/math/sphere_map.h>
#include <lumx/volume/radiance_volume.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace lumx_py {

namespace {

/// One loaded level: set.levels holds exactly this level, with the bundle's units, channels and bounds.
struct LoadedLevel {
  lumx::AplSet set;
  std::size_t index = 0;   ///< level index in the bundle
  int max_resolution = 0;  ///< as requested
  std::once_flag sampler_once;
  std::unique_ptr<lumx::AplEmissionSampler> sampler;

  const lumx::AplLevel& level() const { return set.levels[0]; }
  const lumx::AplEmissionSampler& emission_sampler() {
    std::call_once(sampler_once, [this] { sampler = std::make_unique<lumx::AplEmissionSampler>(set, 0); });
    return *sampler;
  }
};

using LevelPtr = std::shared_ptr<LoadedLevel>;

/// The Python lumx.Level.
struct Level {
  LevelPtr data;
};

/// splitmix64 (Steele, Lea & Flood 2014) of (seed, n) to [0, 1): the per-point random number of the
/// distance rule when the caller gives none. With n the 1-based point number it is the number `lumx eval
/// --points --lod --seed` draws for a points file with one point per line, so both choose alike.
double point_random(std::uint64_t seed, std::uint64_t n) {
  std::uint64_t z = seed * 0x9e3779b97f4a7c15ull + n;
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return double(z >> 11) * (1.0 / 9007199254740992.0);
}

const char* channels_name(lumx::ChannelLayout c) {
  return c == lumx::ChannelLayout::rgb ? "rgb" : "luminance";
}
const char* quantity_name(lumx::PhotometricQuantity q) {
  return q == lumx::PhotometricQuantity::photometric ? "photometric" : "radiometric";
}

/// An (N,) luminance array or, with rgb, the (N, 3) channels.
py::array per_point(const std::vector<glm::dvec3>& values, lumx::ChannelLayout layout, bool rgb) {
  const std::size_t n = values.size();
  if (rgb) {
    py::array_t<double> out({py::ssize_t(n), py::ssize_t(3)});
    double* o = out.mutable_data();
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) o[3 * i + std::size_t(c)] = values[i][c];
    return std::move(out);
  }
  py::array_t<double> out{py::ssize_t(n)};
  double* o = out.mutable_data();
  for (std::size_t i = 0; i < n; ++i) o[i] = lumx::luminance_of(layout, values[i]);
  return std::move(out);
}

py::object result(const std::vector<glm::dvec3>& values, lumx::ChannelLayout layout, bool rgb, bool single) {
  py::array a = per_point(values, layout, rgb);
  if (!single) return std::move(a);
  if (rgb) return a[py::int_(0)];
  return py::float_(lumx::luminance_of(layout, values[0]));
}

/// Unit normals as the CLI's points reader makes them: normalised in double, then evaluated in float.
std::vector<glm::vec3> unit_rows(const Vec3Rows& rows, const char* what) {
  std::vector<glm::vec3> out(rows.count);
  for (std::size_t i = 0; i < rows.count; ++i) {
    const glm::dvec3 v = rows.at(i);
    const double len = glm::length(v);
    if (!(len > 0) || !std::isfinite(len))
      throw py::value_error(std::string(what) + "[" + std::to_string(i) + "]: zero or non-finite vector");
    out[i] = glm::vec3(v / len);
  }
  return out;
}

/// Irradiance of every point on one loaded level.
void irradiance_on(const LoadedLevel& l, const std::vector<glm::vec3>& x, const std::vector<glm::vec3>& n,
                   const std::vector<std::size_t>& which, const lumx::IrradianceOptions& o,
                   std::vector<glm::dvec3>& out, std::size_t& clamped) {
  for (std::size_t i : which) {
    const lumx::IrradianceResult r = lumx::irradiance(l.set, 0, x[i], n.empty() ? glm::vec3(0, 0, 1) : n[i], o);
    out[i] = r.irradiance;
    clamped += r.clamped;
  }
}

std::vector<glm::dvec3> far_field_on(const LoadedLevel& l, const Vec3Rows& d) {
  std::vector<glm::dvec3> out(d.count);
  py::gil_scoped_release release;
  for (std::size_t i = 0; i < d.count; ++i) {
    const glm::dvec3 w = d.at(i);
    const double len = glm::length(w);
    out[i] = len > 0 ? lumx::far_field_intensity(l.level(), glm::vec3(w / len)) : glm::dvec3(0.0);
  }
  return out;
}

class Bundle {
 public:
  explicit Bundle(const std::string& path) {
    py::gil_scoped_release release;
    reader_ = std::make_unique<lumx::BundleReader>(path);
    const lumx::BundleManifest& m = reader_->manifest();
    skeleton_ = reader_->empty_set();
    for (const lumx::BundleLevelInfo& info : m.levels) {
      lumx::AplLevel level;
      level.map_resolution = info.map_resolution;
      level.frame = info.frame;
      level.apls.resize(info.apl_count());
      level.error = info.error;
      skeleton_.levels.push_back(std::move(level));
    }
    cache_.resize(m.levels.size());
  }

  const lumx::BundleManifest& manifest() const { return reader_->manifest(); }
  const std::string& path() const { return reader_->path(); }
  const lumx::AplSet& skeleton() const { return skeleton_; }
  std::size_t level_count() const { return skeleton_.levels.size(); }
  std::uint64_t bytes_read() {
    std::lock_guard<std::mutex> lock(mutex_);
    return reader_->bytes_read();
  }

  std::size_t level_index(const py::object& level) const {
    if (skeleton_.levels.empty()) throw py::value_error("the bundle has no level");
    if (level.is_none()) return skeleton_.levels.size() - 1;
    const long k = level.cast<long>();
    const long n = long(skeleton_.levels.size());
    if (k < -n || k >= n)
      throw py::index_error("level " + std::to_string(k) + ": the bundle has levels 0.." + std::to_string(n - 1));
    return std::size_t(k < 0 ? k + n : k);
  }

  /// The level as loaded before, else loaded at `max_resolution`; `reload` loads again when the cached
  /// one was asked with another resolution. Call without the GIL.
  LevelPtr level(std::size_t k, int max_resolution, bool reload) {
    std::lock_guard<std::mutex> lock(mutex_);
    LevelPtr& slot = cache_.at(k);
    if (slot && (!reload || slot->max_resolution == max_resolution)) return slot;
    auto l = std::make_shared<LoadedLevel>();
    l->set = reader_->empty_set();
    l->set.levels.push_back(reader_->load_level(k, max_resolution));
    l->index = k;
    l->max_resolution = max_resolution;
    slot = l;
    return slot;
  }

  lumx::RadianceVolume load_volume() {
    std::lock_guard<std::mutex> lock(mutex_);
    return reader_->load_volume();
  }
  std::string read_attachment(std::size_t i) {
    std::lock_guard<std::mutex> lock(mutex_);
    return reader_->read_attachment(i);
  }

 private:
  std::unique_ptr<lumx::BundleReader> reader_;
  lumx::AplSet skeleton_;
  std::vector<LevelPtr> cache_;
  std::mutex mutex_;
};

py::array map_view(py::object level_obj, std::size_t apl) {
  const Level& l = level_obj.cast<const Level&>();
  const lumx::AplLevel& level = l.data->level();
  if (apl >= level.apls.size())
    throw py::index_error("apl " + std::to_string(apl) + ": the level has " + std::to_string(level.apls.size()) +
                          " APLs");
  const lumx::SphereMap& map = level.apls[apl].map;
  const py::ssize_t R = map.resolution(), W = map.width(), C = map.channels();
  const py::ssize_t f = sizeof(float);
  py::array a(py::dtype::of<float>(), {R, W, C}, {W * C * f, C * f, f}, map.data(), level_obj);
  // The maps are shared with the bundle's cache and every other view: read-only.
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array readonly(py::array a) {
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array sample_emission(const Level& l, const py::object& u) {
  DoubleArray a = DoubleArray::ensure(u);
  if (!a || a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error("u: expected an (N, 3) array of uniform random numbers in [0, 1)");
  const std::size_t n = std::size_t(a.shape(0));
  const lumx::AplEmissionSampler* sampler = nullptr;
  {
    py::gil_scoped_release release;
    sampler = &l.data->emission_sampler();
  }
  py::list fields;
  fields.append(py::make_tuple("apl", "<i8"));
  fields.append(py::make_tuple("position", "<f4", py::make_tuple(3)));
  fields.append(py::make_tuple("direction", "<f4", py::make_tuple(3)));
  fields.append(py::make_tuple("pdf_apl", "<f4"));
  fields.append(py::make_tuple("pdf_direction", "<f4"));
  fields.append(py::make_tuple("flux", "<f4", py::make_tuple(3)));
  // Packed records (NumPy's default): apl at 0, position 8, direction 20, pdf_apl 32,
  // pdf_direction 36, flux 40; 52 bytes.
  py::array out(py::dtype::from_args(fields), std::vector<py::ssize_t>{py::ssize_t(n)});
  if (out.itemsize() != 52) throw std::logic_error("sample_emission: unexpected record layout");
  char* rec = static_cast<char*>(out.mutable_data());
  const double* ud = a.data();
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < n; ++i) {
      const lumx::EmissionSample s = sampler->sample(float(ud[3 * i]), float(ud[3 * i + 1]), float(ud[3 * i + 2]));
      const std::int64_t apl = s.valid() ? std::int64_t(s.apl) : -1;
      const float values[11] = {s.position.x,  s.position.y,  s.position.z, s.direction.x,
                                s.direction.y, s.direction.z, s.pdf_apl,    s.pdf_direction,
                                s.flux.x,      s.flux.y,      s.flux.z};
      std::memcpy(rec + 52 * i, &apl, sizeof apl);
      std::memcpy(rec + 52 * i + 8, values, sizeof values);
    }
  }
  return out;
}

py::object emission_pdf(const Level& l, const py::object& apl, const py::object& directions) {
  const Vec3Rows d = vec3_rows(directions, "directions");
  py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> ia =
      py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(apl);
  const bool one_per_direction =
      ia && ((ia.ndim() == 1 && std::size_t(ia.shape(0)) == d.count) || (ia.ndim() == 0 && d.single));
  if (!one_per_direction) throw py::value_error("apl: expected one APL index per direction");
  const std::size_t count = l.data->level().size();
  const std::int64_t* ip = ia.data();
  py::array_t<double> out(py::ssize_t(d.count));
  double* o = out.mutable_data();
  {
    py::gil_scoped_release release;
    const lumx::AplEmissionSampler& s = l.data->emission_sampler();
    for (std::size_t i = 0; i < d.count; ++i) {
      if (ip[i] < 0 || std::size_t(ip[i]) >= count) {
        o[i] = 0.0;  // an invalid sample's index
        continue;
      }
      const glm::dvec3 w = d.at(i);
      o[i] = s.pdf(std::size_t(ip[i]), glm::vec3(w / glm::length(w)));
    }
  }
  return scalar_or_array(out, d.single);
}

}  // namespace

void bind_bundle(py::module_& m) {
  py::class_<Level>(m, "Level",
                    "One loaded APL level: anisotropic point lights at positions (m) with intensity maps (cd or "
                    "W/sr) on equal-area sphere maps. Queries evaluate in C++ with the GIL released.")
      .def_property_readonly(
          "index", [](const Level& l) { return l.data->index; }, "level index in the bundle")
      .def_property_readonly("apl_count", [](const Level& l) { return l.data->level().size(); })
      .def("__len__", [](const Level& l) { return l.data->level().size(); })
      .def_property_readonly(
          "map_resolution", [](const Level& l) { return l.data->level().map_resolution; },
          "R of the loaded maps (each map is an R x 2R image)")
      .def_property_readonly(
          "map_frame",
          [](const Level& l) {
            const lumx::MapFrame& frame = l.data->level().frame;
            py::array_t<float> out({py::ssize_t(3), py::ssize_t(3)});
            float* o = out.mutable_data();
            for (int r = 0; r < 3; ++r) {
              const glm::vec3 row = frame.row(r);
              o[3 * r] = row.x, o[3 * r + 1] = row.y, o[3 * r + 2] = row.z;
            }
            return out;
          },
          "3 x 3 rotation from the photometric frame to the maps' frame: a direction w reads the maps at "
          "map_frame @ w, and a map direction m is the photometric direction map_frame.T @ m")
      .def_property_readonly(
          "positions",
          [](const Level& l) {
            const auto& apls = l.data->level().apls;
            py::array_t<float> out({py::ssize_t(apls.size()), py::ssize_t(3)});
            float* o = out.mutable_data();
            for (std::size_t i = 0; i < apls.size(); ++i)
              for (int c = 0; c < 3; ++c) o[3 * i + std::size_t(c)] = apls[i].position[c];
            return out;
          },
          "APL positions, m, (N, 3), in the luminaire's photometric frame")
      .def_property_readonly(
          "flux",
          [](const Level& l) {
            const auto& apls = l.data->level().apls;
            py::array_t<double> out({py::ssize_t(apls.size()), py::ssize_t(3)});
            double* o = out.mutable_data();
            for (std::size_t i = 0; i < apls.size(); ++i)
              for (int c = 0; c < 3; ++c) o[3 * i + std::size_t(c)] = apls[i].flux[c];
            return out;
          },
          "flux per APL and channel, lm or W, (N, 3) (one-channel sets repeat Y)")
      .def_property_readonly(
          "parent",
          [](const Level& l) {
            const auto& apls = l.data->level().apls;
            py::array_t<int> out(py::ssize_t(apls.size()));
            for (std::size_t i = 0; i < apls.size(); ++i) out.mutable_at(py::ssize_t(i)) = apls[i].parent;
            return out;
          },
          "index of each APL's parent in the previous level (-1 in the first)")
      .def_property_readonly(
          "error_table",
          [](const Level& l) {
            const lumx::ErrorTable& e = l.data->level().error;
            return py::make_tuple(
                py::array_t<double>(py::ssize_t(e.relative_distance.size()), e.relative_distance.data()),
                py::array_t<double>(py::ssize_t(e.relative_rmse.size()), e.relative_rmse.data()));
          },
          "(relative distance d, relative RMSE) of the level's irradiance, measured on held-out rays; empty "
          "when the bundle has none")
      .def_property_readonly(
          "map_bytes", [](const Level& l) { return l.data->level().map_bytes(); }, "bytes of map data in memory")
      .def("map", &map_view, py::arg("apl"),
           "APL `apl`'s intensity map, cd or W/sr, as a read-only (R, 2R, channels) float32 view (no copy); "
           "texel (x, y) holds the mean over its equal solid angle 4 pi / (2 R^2) sr. lumx.uv_to_direction "
           "maps texel centres to directions of the maps' frame (map_frame.T turns them photometric).")
      .def(
          "maps",
          [](const Level& l) {
            const lumx::AplLevel& level = l.data->level();
            const py::ssize_t n = py::ssize_t(level.apls.size()), R = level.map_resolution;
            const py::ssize_t C = level.apls.empty() ? 1 : level.apls[0].map.channels();
            py::array_t<float> out({n, R, 2 * R, C});
            float* o = out.mutable_data();
            const std::size_t per = std::size_t(2 * R * R * C);
            for (std::size_t i = 0; i < level.apls.size(); ++i)
              std::copy(level.apls[i].map.data(), level.apls[i].map.data() + per, o + i * per);
            return out;
          },
          "Every map of the level in one (N, R, 2R, channels) float32 array (a copy), cd or W/sr.")
      .def(
          "intensity",
          [](const Level& l, const py::object& directions, bool rgb) {
            const Vec3Rows d = vec3_rows(directions, "directions");
            return result(far_field_on(*l.data, d), l.data->set.channels, rgb, d.single);
          },
          py::arg("directions"), py::arg("rgb") = false,
          "Far-field intensity of the whole level towards each direction (sum of the APLs' maps, positions "
          "ignored), cd or W/sr: (N,) luminance, or (N, 3) channels with rgb=True.")
      .def("sample_emission", &sample_emission, py::arg("u"),
           "Emission samples (light tracing, photon mapping) from an (N, 3) array of uniform numbers in [0, 1): "
           "a structured array with apl (-1 where invalid), position (3,) m, direction (3,), pdf_apl, "
           "pdf_direction (per sr) and flux (3,) = I / (pdf_apl pdf_direction), lm or W; the mean of flux is the "
           "level's flux.")
      .def("pdf", &emission_pdf, py::arg("apl"), py::arg("directions"),
           "Joint density pdf_apl(apl) * pdf_direction(apl, w) (per sr) of emission sampling, for MIS; equals "
           "what sample_emission returned for its samples. 0 for apl = -1.")
      .def(
          "choose_light",
          [](const Level& l, const py::object& points, const py::object& normals, const py::object& u) {
            const Vec3Rows x = vec3_rows(points, "points");
            const Vec3Rows nr = vec3_rows(normals, "normals");
            if (nr.count != x.count) throw py::value_error("normals: one per point");
            DoubleArray ua = vector_of(u, x.count, "u");
            py::array_t<std::int64_t> apl(py::ssize_t(x.count));
            py::array_t<double> prob(py::ssize_t(x.count));
            std::int64_t* ap = apl.mutable_data();
            double* pp = prob.mutable_data();
            const double* up = ua.data();
            {
              py::gil_scoped_release release;
              for (std::size_t i = 0; i < x.count; ++i) {
                const glm::dvec3 nn = nr.at(i);
                const double len = glm::length(nn);
                const glm::vec3 n = len > 0 ? glm::vec3(nn / len) : glm::vec3(0.0f);
                const lumx::LightChoice c = lumx::choose_light(l.data->set, 0, glm::vec3(x.at(i)), n, float(up[i]));
                ap[i] = c.valid() ? std::int64_t(c.apl) : -1;
                pp[i] = c.probability;
              }
            }
            return py::make_tuple(apl, prob);
          },
          py::arg("points"), py::arg("normals"), py::arg("u"),
          "Next-event estimation: one APL per shading point (points (N, 3) m, normals (N, 3), u (N,) in [0, 1)) "
          "with probability proportional to flux * cos / r^2; returns (apl (N,), probability (N,)), apl -1 where "
          "no APL can light the point.")
      .def("__repr__", [](const Level& l) {
        return "<lumx.Level " + std::to_string(l.data->index) + ": " + std::to_string(l.data->level().size()) +
               " APLs, R " + std::to_string(l.data->level().map_resolution) + ">";
      });

  py::class_<lumx::RadianceVolume, std::shared_ptr<lumx::RadianceVolume>>(
      m, "RadianceVolume",
      "The luminaire's glow: a voxel grid (m) of spherical-harmonic radiance coefficients per channel.")
      .def_property_readonly(
          "counts",
          [](const lumx::RadianceVolume& v) { return py::make_tuple(v.counts().x, v.counts().y, v.counts().z); },
          "voxels per axis (nx, ny, nz)")
      .def_property_readonly(
          "lo",
          [](const lumx::RadianceVolume& v) {
            return py::make_tuple(v.bounds().lo.x, v.bounds().lo.y, v.bounds().lo.z);
          },
          "grid lower corner, m")
      .def_property_readonly(
          "hi",
          [](const lumx::RadianceVolume& v) {
            return py::make_tuple(v.bounds().hi.x, v.bounds().hi.y, v.bounds().hi.z);
          },
          "grid upper corner, m")
      .def_property_readonly("voxel_size", &lumx::RadianceVolume::voxel_size, "edge of the cubic voxels, m")
      .def_property_readonly("bands", &lumx::RadianceVolume::bands, "SH bands (coefficients = bands^2)")
      .def_property_readonly("channels", &lumx::RadianceVolume::channels)
      .def_property_readonly(
          "coefficients",
          [](py::object self) {
            const auto& v = self.cast<const lumx::RadianceVolume&>();
            const glm::ivec3 c = v.counts();
            const py::ssize_t q = v.coefficient_count(), ch = v.channels(), f = sizeof(float);
            py::array a(py::dtype::of<float>(), {py::ssize_t(c.z), py::ssize_t(c.y), py::ssize_t(c.x), ch, q},
                        {py::ssize_t(c.y) * c.x * ch * q * f, py::ssize_t(c.x) * ch * q * f, ch * q * f, q * f, f},
                        v.coefficients().data(), self);
            return readonly(a);
          },
          "SH coefficients, read-only view (nz, ny, nx, channels, bands^2), flux unit / (m^2 sr)")
      .def(
          "radiance",
          [](const lumx::RadianceVolume& v, const py::object& points, const py::object& directions) {
            const Vec3Rows x = vec3_rows(points, "points");
            const Vec3Rows d = vec3_rows(directions, "directions");
            if (x.count != d.count) throw py::value_error("directions: one per point");
            py::array_t<double> out({py::ssize_t(x.count), py::ssize_t(3)});
            double* o = out.mutable_data();
            {
              py::gil_scoped_release release;
              for (std::size_t i = 0; i < x.count; ++i) {
                const glm::vec3 r = v.radiance(x.at(i), d.at(i));
                for (int c = 0; c < 3; ++c) o[3 * i + std::size_t(c)] = r[c];
              }
            }
            if (x.single) return py::object(out[py::int_(0)]);
            return py::object(out);
          },
          py::arg("points"), py::arg("directions"),
          "Radiance at points (N, 3) m travelling along directions (N, 3), per channel: (N, 3), in the "
          "bundle's flux unit per m^2 sr (cd/m^2 for lm). One-channel volumes repeat the value.");

  py::class_<Bundle>(m, "Bundle",
                     "A lumx bundle folder: an APL set in levels of detail (and optionally a radiance volume). "
                     "Opening reads manifest.json only; levels load on request, at a chosen map resolution.")
      .def(py::init<const std::string&>(), py::arg("path"),
           "Opens the bundle and reads its manifest. Raises lumx.Error (field names the manifest entry) or "
           "OSError.")
      .def_property_readonly("path", [](Bundle& b) { return b.path(); })
      .def_property_readonly(
          "quantity", [](Bundle& b) { return quantity_name(b.manifest().quantity); },
          "'photometric' (cd, lm, lx) or 'radiometric' (W/sr, W, W/m^2)")
      .def_property_readonly(
          "channels", [](Bundle& b) { return channels_name(b.manifest().channels); },
          "'luminance' (one channel Y) or 'rgb'")
      .def_property_readonly("intensity_unit", [](Bundle& b) { return lumx::intensity_unit(b.manifest().quantity); })
      .def_property_readonly("flux_unit", [](Bundle& b) { return lumx::flux_unit(b.manifest().quantity); })
      .def_property_readonly("irradiance_unit", [](Bundle& b) { return lumx::irradiance_unit(b.manifest().quantity); })
      .def_property_readonly(
          "bounds",
          [](Bundle& b) {
            const lumx::BoundingSphere& s = b.manifest().bounds;
            return py::make_tuple(py::make_tuple(s.center.x, s.center.y, s.center.z), s.radius);
          },
          "bounding sphere ((x, y, z), radius), m: relative distances are |x - centre| / (2 radius)")
      .def_property_readonly("provenance", [](Bundle& b) { return b.manifest().provenance; })
      .def_property_readonly("generator", [](Bundle& b) { return b.manifest().generator; })
      .def_property_readonly("level_count", &Bundle::level_count)
      .def("__len__", &Bundle::level_count)
      .def_property_readonly(
          "apl_counts",
          [](Bundle& b) {
            std::vector<std::size_t> out;
            for (const auto& l : b.manifest().levels) out.push_back(l.apl_count());
            return out;
          },
          "APLs per level, increasing")
      .def_property_readonly(
          "map_resolutions",
          [](Bundle& b) {
            std::vector<std::vector<int>> out;
            for (const auto& l : b.manifest().levels) {
              std::vector<int> r;
              for (const auto& p : l.maps) r.push_back(p.resolution);
              out.push_back(r);
            }
            return out;
          },
          "per level, the stored map resolutions, finest first")
      .def(
          "level_flux",
          [](Bundle& b, const py::object& level) {
            const lumx::BundleLevelInfo& l = b.manifest().levels.at(b.level_index(level));
            glm::dvec3 sum(0.0);
            for (const auto& f : l.flux) sum += f;
            return lumx::luminance_of(b.manifest().channels, sum);
          },
          py::arg("level") = py::none(), "a level's total flux from the manifest, lm or W (no payload read)")
      .def(
          "level_positions",
          [](Bundle& b, const py::object& level) {
            const lumx::BundleLevelInfo& l = b.manifest().levels.at(b.level_index(level));
            py::array_t<float> out({py::ssize_t(l.position.size()), py::ssize_t(3)});
            float* o = out.mutable_data();
            for (std::size_t i = 0; i < l.position.size(); ++i)
              for (int c = 0; c < 3; ++c) o[3 * i + std::size_t(c)] = l.position[i][c];
            return out;
          },
          py::arg("level") = py::none(), "a level's APL positions from the manifest, m, (N, 3) (no payload read)")
      .def_property_readonly("has_volume", [](Bundle& b) { return b.manifest().volume.has_value(); })
      .def_property_readonly("bytes_read", &Bundle::bytes_read, "bytes read from disk so far, manifest included")
      .def_property_readonly(
          "total_bytes", [](Bundle& b) { return b.manifest().total_bytes(); },
          "bytes of the manifest and every payload: what a full load reads")
      .def_property_readonly(
          "attachments",
          [](Bundle& b) {
            std::vector<std::string> names;
            for (const auto& a : b.manifest().attachments) names.push_back(a.first.name);
            return names;
          },
          "names of the files shipped in attachments/ (e.g. far_field.ies)")
      .def(
          "read_attachment",
          [](Bundle& b, const std::string& name) {
            const auto& list = b.manifest().attachments;
            for (std::size_t i = 0; i < list.size(); ++i)
              if (list[i].first.name == name) {
                std::string bytes;
                {
                  py::gil_scoped_release release;
                  bytes = b.read_attachment(i);
                }
                return py::bytes(bytes);
              }
            throw py::key_error(name);
          },
          py::arg("name"), "An attachment's bytes (checksum verified).")
      .def(
          "load_level",
          [](Bundle& b, long level, int max_resolution) {
            const std::size_t k = b.level_index(py::int_(level));
            if (max_resolution < 0) throw py::value_error("max_resolution must be >= 0 (0: full resolution)");
            py::gil_scoped_release release;
            return Level{b.level(k, max_resolution, true)};
          },
          py::arg("level"), py::arg("max_resolution") = 0,
          "Loads one level with maps at the largest stored resolution <= max_resolution (0: full; the coarsest "
          "stored one when max_resolution is below it), reading only that payload. Later queries on this "
          "level use what was loaded last.")
      .def(
          "level",
          [](Bundle& b, const py::object& level) {
            const std::size_t k = b.level_index(level);
            py::gil_scoped_release release;
            return Level{b.level(k, 0, false)};
          },
          py::arg("level") = py::none(),
          "The level as loaded before, or loaded now at full resolution (default: the finest level).")
      .def(
          "irradiance",
          [](Bundle& b, const py::object& points, const py::object& normals, const py::object& level,
             const py::object& lod, const py::object& error_target, const py::object& u, std::uint64_t seed, bool rgb,
             double min_distance) {
            const Vec3Rows x = vec3_rows(points, "points");
            // Evaluated in float, as the CLI does; the level choice sees the points in double, as there.
            std::vector<glm::vec3> xf(x.count), nf;
            for (std::size_t i = 0; i < x.count; ++i) xf[i] = glm::vec3(x.at(i));
            lumx::IrradianceOptions o;
            o.min_distance = min_distance;
            if (normals.is_none()) {
              o.ignore_normal = true;
            } else {
              const Vec3Rows n = vec3_rows(normals, "normals");
              if (n.count != x.count) throw py::value_error("normals: one per point");
              nf = unit_rows(n, "normals");
            }
            const bool by_distance = !lod.is_none() && lod.cast<bool>();
            const bool by_error = !error_target.is_none();
            if ((by_distance || by_error) && !level.is_none())
              throw py::value_error("give level, lod or error_target, not several");
            if (by_distance && by_error) throw py::value_error("give lod or error_target, not both");
            const bool have_u = by_distance && !u.is_none();
            DoubleArray ua;  // (a default array_t is an empty array, not a null handle: have_u says)
            if (have_u) ua = vector_of(u, x.count, "u");
            const double target = by_error ? error_target.cast<double>() : 0.0;
            const std::size_t fixed = b.level_index(level);
            std::vector<glm::dvec3> out(x.count);
            std::size_t clamped = 0;
            {
              py::gil_scoped_release release;
              std::vector<std::vector<std::size_t>> groups(by_distance || by_error ? b.level_count() : 1);
              for (std::size_t i = 0; i < x.count; ++i) {
                std::size_t k = 0;
                if (by_distance) {
                  const double r = have_u ? ua.data()[i] : point_random(seed, i + 1);
                  k = lumx::choose_level_by_distance(b.skeleton(), x.at(i), r);
                } else if (by_error) {
                  k = lumx::choose_level_for_error(b.skeleton(), b.skeleton().relative_distance(x.at(i)), target);
                }
                groups[k].push_back(i);
              }
              for (std::size_t g = 0; g < groups.size(); ++g) {
                if (groups[g].empty()) continue;
                const LevelPtr l = b.level(groups.size() == 1 ? fixed : g, 0, false);
                irradiance_on(*l, xf, nf, groups[g], o, out, clamped);
              }
            }
            return result(out, b.manifest().channels, rgb, x.single);
          },
          py::arg("points"), py::arg("normals") = py::none(), py::kw_only(), py::arg("level") = py::none(),
          py::arg("lod") = py::none(), py::arg("error_target") = py::none(), py::arg("u") = py::none(),
          py::arg("seed") = 1, py::arg("rgb") = false, py::arg("min_distance") = 0.0,
          "Irradiance, lx (or W/m^2), at points (N, 3) m on surfaces with normals (N, 3) (normalised here; "
          "None: no cosine, irradiance on a sphere), without occluders. The level: `level` (default the "
          "finest); lod=True, per point by the distance rule (eq. 6.2) with random numbers u (N,) or, "
          "without u, the numbers `lumx eval --lod --seed` draws for line i + 1; or error_target=e, the "
          "smallest level whose stored error at the point's distance is <= e. Levels not loaded yet load at "
          "full resolution. Returns (N,) luminance, or (N, 3) channels with rgb=True.")
      .def(
          "intensity",
          [](Bundle& b, const py::object& directions, const py::object& level, bool rgb) {
            const Vec3Rows d = vec3_rows(directions, "directions");
            const std::size_t k = b.level_index(level);
            LevelPtr l;
            {
              py::gil_scoped_release release;
              l = b.level(k, 0, false);
            }
            return result(far_field_on(*l, d), b.manifest().channels, rgb, d.single);
          },
          py::arg("directions"), py::kw_only(), py::arg("level") = py::none(), py::arg("rgb") = false,
          "Far-field intensity, cd (or W/sr), towards directions (N, 3): the sum of a level's maps (default the "
          "finest level). (N,) luminance, or (N, 3) with rgb=True.")
      .def(
          "sample_emission",
          [](Bundle& b, const py::object& u, const py::object& level) {
            const std::size_t k = b.level_index(level);
            Level l;
            {
              py::gil_scoped_release release;
              l.data = b.level(k, 0, false);
            }
            return sample_emission(l, u);
          },
          py::arg("u"), py::kw_only(), py::arg("level") = py::none(),
          "Level.sample_emission on a level (default the finest), loaded at full resolution unless loaded "
          "before: samples with position (m), direction, pdfs (per sr) and flux (lm or W).")
      .def(
          "pdf",
          [](Bundle& b, const py::object& apl, const py::object& directions, const py::object& level) {
            const std::size_t k = b.level_index(level);
            Level l;
            {
              py::gil_scoped_release release;
              l.data = b.level(k, 0, false);
            }
            return emission_pdf(l, apl, directions);
          },
          py::arg("apl"), py::arg("directions"), py::kw_only(), py::arg("level") = py::none(),
          "Level.pdf on a level (default the finest): the joint emission density, per sr.")
      .def(
          "load_volume",
          [](Bundle& b) {
            if (!b.manifest().volume) throw py::value_error("the bundle has no radiance volume");
            py::gil_scoped_release release;
            return std::make_shared<lumx::RadianceVolume>(b.load_volume());
          },
          "Reads the radiance volume (lumx.RadianceVolume); ValueError when the bundle has none.")
      .def("__repr__", [](Bundle& b) {
        std::string s = "<lumx.Bundle " + std::to_string(b.level_count()) + " levels (";
        for (std::size_t k = 0; k < b.manifest().levels.size(); ++k)
          s += (k ? ", " : "") + std::to_string(b.manifest().levels[k].apl_count());
        return s + " APLs)>";
      });

  m.def(
      "direction_to_uv",
      [](const py::object& directions) {
        const Vec3Rows d = vec3_rows(directions, "directions");
        py::array_t<double> out({py::ssize_t(d.count), py::ssize_t(2)});
        double* o = out.mutable_data();
        for (std::size_t i = 0; i < d.count; ++i) {
          const glm::dvec3 w = d.at(i);
          const glm::vec2 uv = lumx::sphere_map::direction_to_uv(glm::vec3(w / glm::length(w)));
          o[2 * i] = uv.x;
          o[2 * i + 1] = uv.y;
        }
        if (d.single) return py::object(out[py::int_(0)]);
        return py::object(out);
      },
      py::arg("directions"),
      "Sphere-map coordinates (u, v) in [0, 1]^2 of directions (N, 3): u across the 2R-wide image (left "
      "half z >= 0), v down its R rows. The directions are in the maps' frame: for a level's maps pass "
      "level.map_frame @ w of a photometric direction w (Level.map_frame).");
  m.def(
      "uv_to_direction",
      [](const py::object& uv) {
        DoubleArray a = DoubleArray::ensure(uv);
        if (!a || a.ndim() < 1 || a.shape(a.ndim() - 1) != 2)
          throw py::value_error("uv: expected an array of shape (..., 2)");
        const std::size_t n = std::size_t(a.size() / 2);
        std::vector<py::ssize_t> shape(a.shape(), a.shape() + a.ndim());
        shape.back() = 3;
        py::array_t<double> out(shape);
        double* o = out.mutable_data();
        const double* in = a.data();
        for (std::size_t i = 0; i < n; ++i) {
          const glm::vec3 w = lumx::sphere_map::uv_to_direction(glm::vec2(float(in[2 * i]), float(in[2 * i + 1])));
          for (int c = 0; c < 3; ++c) o[3 * i + std::size_t(c)] = w[c];
        }
        return out;
      },
      py::arg("uv"),
      "Unit directions of sphere-map coordinates (..., 2) -> (..., 3); texel (x, y) of an R map has "
      "its centre at ((x + 0.5) / 2R, (y + 0.5) / R). The directions are in the maps' frame: "
      "level.map_frame.T @ m turns one photometric (Level.map_frame).");
}

}  // namespace lumx_py
