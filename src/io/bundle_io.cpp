// src/io/bundle_io.cpp — writing, partially loading and checking lumx bundles (see lumx/io/bundle_io.h).
#include <lumx/io/bundle_io.h>

#include <lumx/io/atomic_file.h>
#include <lumx/radiance_volume.h>
#include <lumx/version.h>

#include "io/bundle_manifest.h"
#include "io/exr_image.h"
#include "io/sha256.h"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

LUMX_NAMESPACE_BEGIN

namespace fs = std::filesystem;

namespace {

constexpr float kHalfMax = 65504.0f;

[[noreturn]] void fail(const std::string& file, const std::string& field, const std::string& message) {
  throw_at_field(file, field, message);
}

std::string join(const std::string& folder, const std::string& relative) { return (fs::path(folder) / relative).string(); }

/// The level's maps stacked vertically into one image: APL i at rows [i·R, (i+1)·R).
detail::ExrImage stack_maps(const std::vector<const SphereMap*>& maps, ChannelLayout layout) {
  detail::ExrImage image;
  const int R = maps.front()->resolution();
  image.width = 2 * R;
  image.height = R * int(maps.size());
  image.channels = detail::map_channel_names(layout);
  image.pixels.reserve(std::size_t(image.width) * image.height * image.channels.size());
  for (const SphereMap* m : maps) image.pixels.insert(image.pixels.end(), m->values().begin(), m->values().end());
  return image;
}

bool choose_half(float max_value, MapPixelType type, const std::string& what) {
  switch (type) {
    case MapPixelType::half:
      if (max_value > kHalfMax)
        fail(what, "pixel_type", "largest value " + std::to_string(max_value) +
                                     " exceeds half's range (65504); write float or automatic");
      return true;
    case MapPixelType::float32: return false;
    // Half keeps 11 significant bits for values in [2^-14, 65504]. Automatic uses it when the peak is in
    // [2^-4, 65504], so everything down to 2^-10 of the peak keeps full precision; otherwise float.
    case MapPixelType::automatic: return max_value <= kHalfMax && max_value >= 0.0625f;
  }
  return false;
}

BundlePayload write_payload(const std::string& folder, const std::string& relative, const detail::ExrImage& image) {
  BundlePayload p;
  p.file = relative;
  const std::string bytes = detail::encode_exr(image);
  p.bytes = bytes.size();
  p.sha256 = detail::sha256_hex(bytes);
  p.pixel_type = image.half ? "half" : "float";
  write_file_atomically(join(folder, relative), bytes);
  return p;
}

void fsync_folder(const std::string& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);  // best effort: some file systems refuse to sync folders (EINVAL)
  ::close(fd);
}

std::string temporary_sibling(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  return (target.parent_path() / ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                                  std::to_string(counter++)))
      .string();
}

}  // namespace

std::uint64_t BundleManifest::total_bytes() const {
  std::uint64_t total = manifest_bytes;
  for (const BundleLevelInfo& l : levels)
    for (const BundlePayload& p : l.maps) total += p.bytes;
  if (volume) total += volume->payload.bytes;
  return total;
}

// ---------------------------------------------------------------------------------------------- writing

void write_bundle(const std::string& path, const AplSet& set, const RadianceVolume* volume,
                  const BundleWriteOptions& options) {
  if (const auto problems = check_apl_set(set); !problems.empty())
    fail(path, "APL set", problems.front() + (problems.size() > 1 ? " (and " + std::to_string(problems.size() - 1) + " more)" : ""));
  const fs::path target = fs::absolute(fs::path(path)).lexically_normal();
  if (target.filename().empty()) fail(path, "path", "names no folder");
  std::error_code ec;
  const bool exists = fs::exists(target, ec);
  if (exists && (!fs::is_directory(target) || !fs::exists(target / bundle::kManifestName)))
    fail(path, "path", "exists and is not a lumx bundle; refusing to replace it");

  const std::string tmp = temporary_sibling(target);
  try {
    fs::create_directories(fs::path(tmp) / "levels");
    BundleManifest m;
    m.generator = std::string("lumx ") + kLibraryVersion;
    m.quantity = set.quantity;
    m.channels = set.channels;
    m.bounds = set.bounds;
    m.provenance = set.provenance;
    for (std::size_t k = 0; k < set.levels.size(); ++k) {
      const AplLevel& level = set.levels[k];
      BundleLevelInfo info;
      info.map_resolution = level.map_resolution;
      info.error = level.error;
      for (const Apl& a : level.apls) {
        info.position.push_back(a.position);
        info.flux.push_back(a.flux);
        info.parent.push_back(a.parent);
      }
      std::vector<SphereMap> reduced;  // the current mip's maps (empty: use the level's own)
      int R = level.map_resolution;
      while (true) {
        std::vector<const SphereMap*> maps;
        float max_value = 0;
        for (std::size_t i = 0; i < level.apls.size(); ++i) {
          maps.push_back(reduced.empty() ? &level.apls[i].map : &reduced[i]);
          max_value = std::max(max_value, maps.back()->max_value());
        }
        detail::ExrImage image = stack_maps(maps, set.channels);
        char name[64];
        std::snprintf(name, sizeof name, "levels/level%02zu_n%05zu_r%04d.exr", k, level.apls.size(), R);
        image.half = choose_half(max_value, options.pixel_type, path + "/" + name);
        BundlePayload p = write_payload(tmp, name, image);
        p.resolution = R;
        info.maps.push_back(p);
        if (options.min_stored_resolution <= 0 || R % 2 != 0 || R / 2 < options.min_stored_resolution) break;
        std::vector<SphereMap> next;
        for (const SphereMap* map : maps) next.push_back(map->downsampled());
        reduced = std::move(next);
        R /= 2;
      }
      m.levels.push_back(std::move(info));
    }
    if (volume) {
      BundleVolumeInfo v;
      v.lo = volume->bounds().lo;
      v.hi = volume->bounds().hi;
      v.counts = volume->counts();
      v.voxel_size = volume->voxel_size();
      v.bands = volume->bands();
      v.channels = volume->channels();
      v.window = volume->window();
      detail::ExrImage image;
      image.width = v.counts.x;
      image.height = v.counts.y * v.counts.z;
      image.channels = detail::volume_channel_names(v.channels, v.bands);
      image.half = false;  // SH coefficients are signed and noise-sensitive: float32 (000 §4.6)
      image.pixels = volume->coefficients();
      for (float c : image.pixels)
        if (!std::isfinite(c)) fail(path, "volume", "a coefficient is not finite");
      v.payload = write_payload(tmp, "volume.exr", image);
      m.volume = v;
    }
    write_file_atomically(join(tmp, bundle::kManifestName), detail::manifest_to_json(m));
    fsync_folder(tmp + "/levels");
    fsync_folder(tmp);

    if (exists) {
      // Swap the complete new folder with the old one in one step, then delete the old one.
      if (::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) != 0)
        fail(path, "rename", std::string("cannot swap in the new bundle: ") + std::strerror(errno));
      fs::remove_all(tmp, ec);
    } else if (::rename(tmp.c_str(), target.c_str()) != 0) {
      fail(path, "rename", std::string("cannot move the new bundle in place: ") + std::strerror(errno));
    }
    fsync_folder(target.parent_path().string());
  } catch (const Error&) {
    fs::remove_all(tmp, ec);
    throw;
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    fail(path, "write", e.what());
  }
}

// ---------------------------------------------------------------------------------------------- reading

BundleReader::BundleReader(const std::string& path, const BundleLimits& limits) : path_(path), limits_(limits) {
  const std::string manifest_path = join(path, bundle::kManifestName);
  std::error_code ec;
  if (!fs::is_directory(path, ec)) fail(path, "bundle", "is not a folder");
  if (!fs::is_regular_file(manifest_path, ec)) fail(manifest_path, "manifest", "missing");
  const std::string text = read_file_bounded(manifest_path, std::size_t(limits.max_manifest_bytes));
  bytes_read_ += text.size();
  manifest_ = detail::parse_manifest(text, manifest_path, limits);
}

std::string BundleReader::read_payload(const BundlePayload& p, const std::string& field) const {
  const std::string file = join(path_, p.file);
  std::error_code ec;
  // The payload must be a regular file inside the bundle even after resolving symbolic links.
  const fs::path real = fs::weakly_canonical(file, ec);
  const fs::path root = fs::weakly_canonical(path_, ec);
  const std::string rel = real.lexically_relative(root).string();
  if (ec || rel.empty() || rel.rfind("..", 0) == 0) fail(file, field + "/file", "resolves outside the bundle");
  if (!fs::is_regular_file(real, ec)) fail(file, field + "/file", "payload missing");
  const std::uint64_t size = fs::file_size(real, ec);
  if (ec || size != p.bytes)
    fail(file, field + "/bytes", "file has " + std::to_string(size) + " bytes, the manifest says " + std::to_string(p.bytes));
  std::string bytes = read_file_bounded(real.string(), std::size_t(p.bytes));
  bytes_read_ += bytes.size();
  if (bytes.size() != p.bytes) fail(file, field + "/bytes", "file changed while being read");
  if (detail::sha256_hex(bytes) != p.sha256) fail(file, field + "/sha256", "checksum mismatch: the payload is corrupted");
  return bytes;
}

AplSet BundleReader::empty_set() const {
  AplSet set;
  set.quantity = manifest_.quantity;
  set.channels = manifest_.channels;
  set.bounds = manifest_.bounds;
  set.provenance = manifest_.provenance;
  return set;
}

AplLevel BundleReader::load_level(std::size_t k, int max_resolution) const {
  if (k >= manifest_.levels.size())
    fail(path_, "level", std::to_string(k) + " does not exist (the bundle has " + std::to_string(manifest_.levels.size()) + ")");
  const BundleLevelInfo& info = manifest_.levels[k];
  std::size_t pick = info.maps.size() - 1;  // the coarsest, unless a finer one fits the limit
  if (max_resolution <= 0) pick = 0;
  else
    for (std::size_t i = 0; i < info.maps.size(); ++i)
      if (info.maps[i].resolution <= max_resolution) {
        pick = i;
        break;
      }
  const BundlePayload& payload = info.maps[pick];
  const std::string field = "/levels/" + std::to_string(k) + "/maps/" + std::to_string(pick);
  const std::string bytes = read_payload(payload, field);
  const std::string file = join(path_, payload.file);
  const int R = payload.resolution;
  const std::size_t n = info.apl_count();
  const auto names = detail::map_channel_names(manifest_.channels);
  detail::ExrImage image = detail::decode_exr(bytes, file, 2 * R, R * int(n), names);
  if (image.half != (payload.pixel_type == "half"))
    fail(file, field + "/pixel_type", "the manifest says " + payload.pixel_type + ", the image disagrees");

  AplLevel level;
  level.map_resolution = R;
  level.error = info.error;
  level.apls.resize(n);
  const int nc = channel_count(manifest_.channels);
  const std::size_t per_map = std::size_t(2) * R * R * nc;
  double level_flux = 0;
  for (const glm::dvec3& f : info.flux) level_flux += luminance_of(manifest_.channels, f);
  for (std::size_t i = 0; i < n; ++i) {
    Apl& a = level.apls[i];
    a.position = info.position[i];
    a.flux = info.flux[i];
    a.parent = info.parent[i];
    a.map = SphereMap(R, nc);
    std::copy(image.pixels.begin() + std::ptrdiff_t(i * per_map), image.pixels.begin() + std::ptrdiff_t((i + 1) * per_map),
              a.map.values().begin());
    int bx = 0, by = 0, bc = 0;
    if (!a.map.all_finite_nonnegative(&bx, &by, &bc))
      fail(file, "APL " + std::to_string(i) + " texel (" + std::to_string(bx) + ", " + std::to_string(by) + ")",
           "negative or not finite");
  }
  // Values first (above), then consistency with the manifest: a NaN is reported as itself, not as the
  // flux mismatch it causes.
  for (std::size_t i = 0; i < n; ++i) {
    const Apl& a = level.apls[i];
    // The manifest's flux must be the map's integral (half keeps 2^-11 relative per texel; see choose_half).
    const double map_flux = luminance_of(manifest_.channels, a.map.integral());
    const double stated = luminance_of(manifest_.channels, a.flux);
    if (std::abs(map_flux - stated) > 2e-3 * stated + 1e-5 * level_flux)
      fail(file, "/levels/" + std::to_string(k) + "/flux/" + std::to_string(i),
           "manifest flux " + std::to_string(stated) + " but the map integrates to " + std::to_string(map_flux));
  }
  return level;
}

AplSet BundleReader::load(const std::vector<std::size_t>& levels, int max_resolution) const {
  std::vector<std::size_t> chosen = levels;
  if (chosen.empty())
    for (std::size_t k = 0; k < manifest_.levels.size(); ++k) chosen.push_back(k);
  AplSet set = empty_set();
  std::size_t previous = std::size_t(-1);
  for (std::size_t k : chosen) {
    if (previous != std::size_t(-1) && k <= previous) fail(path_, "levels", "requested levels must increase");
    AplLevel level = load_level(k, max_resolution);
    // Parent links name the manifest's previous level; keep them only if that level is loaded just before.
    if (set.levels.empty() || previous + 1 != k)
      for (Apl& a : level.apls) a.parent = -1;
    set.levels.push_back(std::move(level));
    previous = k;
  }
  return set;
}

RadianceVolume BundleReader::load_volume() const {
  if (!manifest_.volume) fail(path_, "/volume", "the bundle has no radiance volume");
  const BundleVolumeInfo& v = *manifest_.volume;
  const std::string bytes = read_payload(v.payload, "/volume");
  const std::string file = join(path_, v.payload.file);
  detail::ExrImage image = detail::decode_exr(bytes, file, v.counts.x, v.counts.y * v.counts.z,
                                              detail::volume_channel_names(v.channels, v.bands));
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    if (!std::isfinite(image.pixels[i])) fail(file, "coefficient " + std::to_string(i), "not finite");
  RadianceVolume volume = RadianceVolume::from_grid(v.lo, v.counts, v.voxel_size, v.bands, v.channels);
  volume.set_window(v.window);
  if (volume.coefficients().size() != image.pixels.size()) fail(file, "/volume", "coefficient count mismatch");
  volume.set_coefficients(std::move(image.pixels));
  return volume;
}

// ---------------------------------------------------------------------------------------------- checking

std::vector<Diagnostic> check_bundle(const std::string& path, double flux_tolerance) {
  std::vector<Diagnostic> out;
  auto note = [&](const std::string& file, const std::string& field, const std::string& message) {
    Diagnostic d;
    d.file = file;
    d.field = field;
    d.message = message;
    out.push_back(std::move(d));
  };
  std::optional<BundleReader> reader;
  try {
    reader.emplace(path);
  } catch (const Error& e) {
    out.push_back(e.diagnostic());
    return out;
  } catch (const std::exception& e) {
    note(path, "bundle", e.what());
    return out;
  }
  const BundleManifest& m = reader->manifest();
  AplSet set = reader->empty_set();
  bool all_levels = true;
  for (std::size_t k = 0; k < m.levels.size(); ++k) {
    // Every stored resolution is read (checksum, decode, values, flux); the full one is kept.
    for (std::size_t p = 0; p < m.levels[k].maps.size(); ++p) {
      try {
        const int R = m.levels[k].maps[p].resolution;
        AplLevel level = reader->load_level(k, R);
        if (p == 0) set.levels.push_back(std::move(level));
      } catch (const Error& e) {
        out.push_back(e.diagnostic());
        if (p == 0) all_levels = false;
      } catch (const std::exception& e) {
        note(join(path, m.levels[k].maps[p].file), "payload", e.what());
        if (p == 0) all_levels = false;
      }
    }
  }
  if (reader->has_volume()) {
    try {
      reader->load_volume();
    } catch (const Error& e) {
      out.push_back(e.diagnostic());
    } catch (const std::exception& e) {
      note(join(path, m.volume->payload.file), "volume", e.what());
    }
  }
  if (!all_levels) return out;
  const std::string manifest = join(path, bundle::kManifestName);
  for (const std::string& problem : check_apl_set(set, flux_tolerance)) note(manifest, "APL set", problem);
  const double first = luminance_of(set.channels, set.levels.front().flux());
  for (std::size_t k = 1; k < set.levels.size(); ++k) {
    const double f = luminance_of(set.channels, set.levels[k].flux());
    if (std::abs(f - first) > flux_tolerance * std::abs(first))
      note(manifest, "/levels/" + std::to_string(k),
           "flux " + std::to_string(f) + " differs from level 0's " + std::to_string(first) + " by more than " +
               std::to_string(flux_tolerance * 100) + " %");
  }
  return out;
}

LUMX_NAMESPACE_END
