// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/io/bundle/bundle_io.cpp — writing, partially loading and checking lumx bundles (see lumx/io/bundle_io.h).
#include <lumx/io/bundle_io.h>

#include <lumx/io/atomic_file.h>
#include <lumx/model/apl_model.h>
#include <lumx/volume/radiance_volume.h>
#include <lumx/version.h>

#include "io/bundle/bundle_manifest.h"
#include "io/bundle/exr_image.h"
#include "io/bundle/sha256.h"

#include <nlohmann/json.hpp>
#include <half.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <stdio.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>

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

/// True when rounding every map to half changes no map's integral by more than 1e-4 (relative): values
/// in half's subnormal range can lose several per cent each, which would break the manifest's flux.
bool half_keeps_flux(const std::vector<const SphereMap*>& maps) {
  for (const SphereMap* m : maps) {
    double exact = 0, rounded = 0;
    for (float v : m->values()) {
      exact += double(v);
      rounded += double(float(Imath::half(v)));
    }
    if (std::abs(rounded - exact) > 1e-4 * std::abs(exact)) return false;
  }
  return true;
}

/// Writes one file of a bundle being assembled in the scratch folder `folder`. A failure names the file as
/// part of `bundle`, the path the caller asked for, not the scratch folder that is about to be removed.
void write_scratch_file(const std::string& folder, const std::string& relative, std::string_view bytes,
                        const std::string& bundle) {
  try {
    write_file_atomically(join(folder, relative), bytes);
  } catch (const Error& e) {
    fail(bundle + "/" + relative, e.diagnostic().field, "while writing the new bundle: " + e.diagnostic().message);
  }
}

BundlePayload write_payload(const std::string& folder, const std::string& relative, const detail::ExrImage& image,
                            const std::string& bundle) {
  BundlePayload p;
  p.file = relative;
  const std::string bytes = detail::encode_exr(image);
  p.bytes = bytes.size();
  p.sha256 = detail::sha256_hex(bytes);
  p.pixel_type = image.half ? "half" : "float";
  write_scratch_file(folder, relative, bytes, bundle);
  return p;
}


std::string temporary_sibling(const fs::path& target) { return temporary_sibling_name(target.string()); }

/// The folder to write: absolute, normalised, without a trailing separator; a symbolic link is followed
/// so that the bundle it points to is replaced and the link keeps pointing at it.
fs::path resolve_target(const std::string& path) {
  fs::path target = fs::absolute(fs::path(path)).lexically_normal();
  if (target.filename().empty()) target = target.parent_path();  // "lamp.lumx/" names lamp.lumx
  if (target.filename().empty() || target == target.root_path()) fail(path, "path", "names no folder");
  std::error_code ec;
  if (fs::is_symlink(target, ec)) target = fs::canonical(target);
  return target;
}

/// Refuses to replace anything but a lumx bundle: a folder whose manifest says "format": "lumx-bundle"
/// and that holds nothing but what a bundle holds (so a user's folder is never swapped out and deleted).
void require_replaceable_bundle(const fs::path& target, const std::string& path) {
  const std::string refuse = "exists and is not a lumx bundle; refusing to replace it";
  std::error_code ec;
  if (!fs::is_directory(target, ec)) fail(path, "path", refuse);
  bool is_bundle = false;
  try {
    const std::string text = read_file_bounded((target / bundle::kManifestName).string(), 64u << 20);
    const nlohmann::json j = nlohmann::json::parse(text);
    is_bundle = j.is_object() && j.value("format", "") == bundle::kFormatName;
  } catch (const std::exception&) {
    is_bundle = false;
  }
  if (!is_bundle) fail(path, "path", refuse + " (no lumx manifest.json)");
  for (const auto& e : fs::directory_iterator(target)) {
    const std::string name = e.path().filename().string();
    const bool expected = (name == bundle::kManifestName && e.is_regular_file()) ||
                          (name == "volume.exr" && e.is_regular_file()) ||
                          ((name == "levels" || name == "attachments" || name == "models") && e.is_directory());
    if (!expected) fail(path, "path", refuse + " (it holds \"" + name + "\")");
  }
  if (fs::is_directory(target / "attachments"))
    for (const auto& e : fs::directory_iterator(target / "attachments"))
      if (!e.is_regular_file() || !detail::is_attachment_name(e.path().filename().string()))
        fail(path, "path", refuse + " (attachments/ holds \"" + e.path().filename().string() + "\")");
  if (fs::is_directory(target / "models"))
    for (const auto& m : fs::directory_iterator(target / "models")) {
      if (!m.is_directory() || !detail::is_attachment_name(m.path().filename().string()))
        fail(path, "path", refuse + " (models/ holds \"" + m.path().filename().string() + "\")");
      for (const auto& e : fs::directory_iterator(m.path()))
        if (!e.is_regular_file() || !detail::is_attachment_name(e.path().filename().string()))
          fail(path, "path", refuse + " (models/" + m.path().filename().string() + "/ holds \"" +
                                 e.path().filename().string() + "\")");
    }
  if (fs::is_directory(target / "levels"))
    for (const auto& e : fs::directory_iterator(target / "levels"))
      if (!e.is_regular_file() || e.path().extension() != ".exr")
        fail(path, "path", refuse + " (levels/ holds \"" + e.path().filename().string() + "\")");
}

/// Replaces `target` (an existing bundle) by `fresh`: one atomic swap where the file system supports
/// renameat2(RENAME_EXCHANGE); otherwise the old bundle is first renamed aside, which leaves a short
/// window in which `target` does not exist. Either way the old bundle ends up at `fresh` and is deleted.
void swap_in(const std::string& fresh, const fs::path& target, const std::string& path) {
  if (::renameat2(AT_FDCWD, fresh.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0) return;
  if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP)
    fail(path, "rename", std::string("cannot swap in the new bundle: ") + std::strerror(errno));
  const std::string aside = temporary_sibling(target);
  if (::rename(target.c_str(), aside.c_str()) != 0)
    fail(path, "rename", std::string("cannot move the old bundle aside: ") + std::strerror(errno));
  if (::rename(fresh.c_str(), target.c_str()) != 0) {
    const int err = errno;
    ::rename(aside.c_str(), target.c_str());  // put the old one back
    fail(path, "rename", std::string("cannot move the new bundle in place: ") + std::strerror(err));
  }
  if (::rename(aside.c_str(), fresh.c_str()) != 0) fs::remove_all(aside);
}

// The payloads a codec adds while its model is written: models/NAME/PAYLOAD in the temporary folder.
class ModelSink final : public ModelPayloadSink {
 public:
  ModelSink(const std::string& tmp, const std::string& model, const std::string& bundle, BundleModelInfo& info)
      : tmp_(tmp), model_(model), bundle_(bundle), info_(info) {}
  void add(const std::string& name, const std::string& bytes) override {
    const std::string field = "models/" + model_ + "/" + name;
    if (!detail::is_attachment_name(name)) fail(bundle_, field, "a payload name must be 1-128 of [A-Za-z0-9._-]");
    for (const auto& [other, p] : info_.payloads)
      if (other == name) fail(bundle_, field, "payload \"" + name + "\" is added twice");
    if (info_.payloads.size() >= BundleLimits{}.max_model_payloads) fail(bundle_, field, "more payloads than BundleLimits::max_model_payloads");
    if (bytes.size() > BundleLimits{}.max_payload_bytes) fail(bundle_, field, "larger than BundleLimits::max_payload_bytes");
    BundlePayload p;
    p.file = field;
    p.bytes = bytes.size();
    p.sha256 = detail::sha256_hex(bytes);
    fs::create_directories(fs::path(tmp_) / "models" / model_);
    write_scratch_file(tmp_, p.file, bytes, bundle_);
    info_.payloads.emplace_back(name, std::move(p));
  }

 private:
  const std::string& tmp_;
  std::string model_;
  const std::string& bundle_;
  BundleModelInfo& info_;
};

}  // namespace

std::uint64_t BundleManifest::total_bytes() const {
  std::uint64_t total = manifest_bytes;
  for (const BundleLevelInfo& l : levels)
    for (const BundlePayload& p : l.maps) total += p.bytes;
  if (volume) total += volume->payload.bytes;
  for (const auto& a : attachments) total += a.second.bytes;
  for (const BundleModelInfo& m : models) total += m.payload_bytes();
  return total;
}

// ---------------------------------------------------------------------------------------------- writing

void write_bundle(const std::string& path, const AplSet& set, const RadianceVolume* volume,
                  const BundleWriteOptions& options) {
  if (const auto problems = check_apl_set(set); !problems.empty())
    fail(path, "APL set", problems.front() + (problems.size() > 1 ? " (and " + std::to_string(problems.size() - 1) + " more)" : ""));
  const fs::path target = resolve_target(path);
  std::error_code ec;
  const bool exists = fs::exists(target, ec);
  if (exists) require_replaceable_bundle(target, path);

  remove_stale_temporaries(target.string());  // of a writer killed mid-write
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
      info.frame = level.frame;
      info.error = level.error;
      for (const Apl& a : level.apls) {
        info.position.push_back(a.position);
        info.flux.push_back(a.flux);
        info.parent.push_back(a.parent);
        info.mask.push_back(-1);
        if (!a.mask) continue;
        // Each mask once, however many APLs share it.
        auto same = std::find(m.masks.begin(), m.masks.end(), a.mask);
        if (same == m.masks.end()) same = m.masks.insert(m.masks.end(), a.mask);
        info.mask.back() = int(same - m.masks.begin());
      }
      if (std::find_if(info.mask.begin(), info.mask.end(), [](int i) { return i >= 0; }) == info.mask.end())
        info.mask.clear();
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
        if (image.half && options.pixel_type == MapPixelType::automatic && !half_keeps_flux(maps)) image.half = false;
        BundlePayload p = write_payload(tmp, name, image, path);
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
      v.payload = write_payload(tmp, "volume.exr", image, path);
      m.volume = v;
    }
    if (!options.attachments.empty()) fs::create_directories(fs::path(tmp) / "attachments");
    for (const BundleAttachment& a : options.attachments) {
      if (!detail::is_attachment_name(a.name)) fail(path, "attachments", "\"" + a.name + "\" is not a valid file name");
      for (const auto& [other, payload] : m.attachments)
        if (other.name == a.name) fail(path, "attachments", "\"" + a.name + "\" is given twice");
      BundlePayload p;
      p.file = "attachments/" + a.name;
      p.bytes = a.bytes.size();
      p.sha256 = detail::sha256_hex(a.bytes);
      write_scratch_file(tmp, p.file, a.bytes, path);
      m.attachments.emplace_back(BundleAttachment{a.name, a.media_type, {}}, p);
    }
    for (std::size_t i = 0; i < options.models.size(); ++i) {
      const auto& [name, model] = options.models[i];
      const std::string at = "models/" + std::to_string(i);
      if (!model) fail(path, at, "no model given");
      if (!detail::is_attachment_name(name)) fail(path, at + "/name", "\"" + name + "\" is not 1-128 of [A-Za-z0-9._-]");
      for (const BundleModelInfo& other : m.models)
        if (other.name == name) fail(path, at + "/name", "\"" + name + "\" is given twice");
      const std::string type = model->type();
      const ModelType* t = find_model_type(type);
      if (!t) fail(path, at + "/type", "no representation is registered as \"" + type + "\"");
      if (!t->write) fail(path, at + "/type", "\"" + type + "\" is stored by the bundle itself, not as a model");
      BundleModelInfo info;
      info.name = name;
      info.type = type;
      ModelSink sink(tmp, name, path, info);
      info.section = t->write(*model, sink);
      if (!detail::is_json_object_text(info.section))
        fail(path, at + "/section", "the codec of \"" + type + "\" wrote no JSON object");
      m.models.push_back(std::move(info));
    }
    // The writer's output must be what its reader accepts: parse it back before anything is replaced.
    // Earlier readers read a set without masks (version 2) and one without models (version 3).
    m.format_version = !m.models.empty() ? 4 : m.masks.empty() ? 2 : 3;
    const std::string manifest_text = detail::manifest_to_json(m);
    detail::parse_manifest(manifest_text, path + "/" + bundle::kManifestName, BundleLimits{});
    write_scratch_file(tmp, bundle::kManifestName, manifest_text, path);
    sync_folder(tmp + "/levels", path, false);
    for (const BundleModelInfo& info : m.models)
      if (!info.payloads.empty()) sync_folder(tmp + "/models/" + info.name, path, false);
    if (!m.models.empty()) sync_folder(tmp + "/models", path, false);
    sync_folder(tmp, path, false);

    if (exists) {
      swap_in(tmp, target, path);  // the old bundle is now at tmp
      fs::remove_all(tmp, ec);
    } else if (::rename(tmp.c_str(), target.c_str()) != 0) {
      fail(path, "rename", std::string("cannot move the new bundle in place: ") + std::strerror(errno));
    }
    // After the swap the new bundle is in place: a failure here is reported, and leaves it whole.
    sync_folder(target.parent_path().string(), path, true);
  } catch (const Error&) {
    fs::remove_all(tmp, ec);
    throw;
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    fail(path, "write", e.what());
  }
}

// ---------------------------------------------------------------------------------------------- reading

namespace {

/// Reads a whole file opened with `fd` (closed on return), refusing anything but a regular file of
/// exactly `expected` bytes (or at most `limit` bytes, the BundleLimits member `limit_name`, when expected is 0).
std::string read_fd(int fd, const std::string& file, const std::string& field, std::uint64_t expected,
                    std::uint64_t limit, const char* limit_name = "the limit") {
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) fail(file, field, "not a regular file");
  const std::uint64_t size = std::uint64_t(st.st_size);
  if (expected > 0 && size != expected)
    fail(file, field + "/bytes", "file has " + std::to_string(size) + " bytes, the manifest says " + std::to_string(expected));
  if (expected == 0 && size > limit)
    fail(file, field, "file has " + std::to_string(size) + " bytes, more than " + limit_name + " (" + std::to_string(limit) + ")");
  std::string bytes(std::size_t(size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, &bytes[done], bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail(file, field, "file changed or could not be read while reading");
    done += std::size_t(n);
  }
  return bytes;
}

/// Opens `relative` ('/'-separated) below the folder `dir_fd` without following symbolic links in any
/// component, so a payload cannot lead outside the bundle however the folder changes meanwhile.
int open_inside(int dir_fd, const std::string& relative, const std::string& file, const std::string& field) {
  int current = dir_fd;
  std::size_t start = 0;
  while (true) {
    const std::size_t slash = relative.find('/', start);
    const std::string part = relative.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    const bool last = slash == std::string::npos;
    const int flags = O_RDONLY | O_CLOEXEC | O_NOFOLLOW | (last ? 0 : O_DIRECTORY);
    const int fd = part.empty() || part == "." || part == ".." ? (errno = EINVAL, -1) : ::openat(current, part.c_str(), flags);
    const int err = errno;
    if (current != dir_fd) ::close(current);
    if (fd < 0) {
      if (err == ENOENT) fail(file, field, "payload missing");
      if (err == ELOOP || err == ENOTDIR) fail(file, field, "is or passes through a symbolic link (payloads must be files inside the bundle)");
      fail(file, field, std::string("cannot open: ") + std::strerror(err));
    }
    if (last) return fd;
    current = fd;
    start = slash + 1;
  }
}

}  // namespace

BundleReader::BundleReader(const std::string& path, const BundleLimits& limits) : path_(path), limits_(limits) {
  const std::string manifest_path = join(path, bundle::kManifestName);
  folder_fd_ = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (folder_fd_ < 0) fail(path, "bundle", errno == ENOENT ? "does not exist" : "is not a folder");
  try {
    const int fd = open_inside(folder_fd_, bundle::kManifestName, manifest_path, "manifest");
    const std::string text =
        read_fd(fd, manifest_path, "manifest", 0, limits.max_manifest_bytes, "BundleLimits::max_manifest_bytes");
    bytes_read_ += text.size();
    manifest_ = detail::parse_manifest(text, manifest_path, limits);
  } catch (...) {  // no destructor runs for a constructor that throws (fuzz_bundle ran out of descriptors)
    ::close(folder_fd_);
    folder_fd_ = -1;
    throw;
  }
}

BundleReader::~BundleReader() {
  if (folder_fd_ >= 0) ::close(folder_fd_);
}

BundleReader::BundleReader(BundleReader&& other) noexcept
    : path_(std::move(other.path_)),
      limits_(other.limits_),
      manifest_(std::move(other.manifest_)),
      bytes_read_(other.bytes_read_),
      folder_fd_(other.folder_fd_) {
  other.folder_fd_ = -1;
}

std::string BundleReader::read_payload(const BundlePayload& p, const std::string& field) const {
  const std::string file = join(path_, p.file);
  const int fd = open_inside(folder_fd_, p.file, file, field + "/file");
  std::string bytes = read_fd(fd, file, field, p.bytes, p.bytes);
  bytes_read_ += bytes.size();
  if (detail::sha256_hex(bytes) != p.sha256)
    fail(file, field + "/sha256", "checksum mismatch: the payload is corrupted (or was replaced after the manifest was read)");
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
  detail::ExrReader image(bytes, file, 2 * R, R * int(n), names);
  if (image.half() != (payload.pixel_type == "half"))
    fail(file, field + "/pixel_type", "the manifest says " + payload.pixel_type + ", the image disagrees");

  AplLevel level;
  level.map_resolution = R;
  level.frame = info.frame;
  level.error = info.error;
  level.apls.resize(n);
  const int nc = channel_count(manifest_.channels);
  double level_flux = 0;
  for (const glm::dvec3& f : info.flux) level_flux += luminance_of(manifest_.channels, f);
  for (std::size_t i = 0; i < n; ++i) {
    Apl& a = level.apls[i];
    a.position = info.position[i];
    a.flux = info.flux[i];
    a.parent = info.parent[i];
    if (!info.mask.empty() && info.mask[i] >= 0) a.mask = manifest_.masks.at(std::size_t(info.mask[i]));
    a.map = SphereMap(R, nc);
    image.read_rows(int(i) * R, int(i + 1) * R - 1, a.map.data());  // each map decodes into its own storage
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
  refresh_coverages(level);  // a masked APL's lit fractions at the resolution loaded
  return level;
}

AplSet BundleReader::load(const std::vector<std::size_t>& levels, int max_resolution) const {
  std::vector<std::size_t> chosen = levels;
  if (chosen.empty())
    for (std::size_t k = 0; k < manifest_.levels.size(); ++k) chosen.push_back(k);
  std::uint64_t decoded = 0;
  for (std::size_t k : chosen) {
    if (k >= manifest_.levels.size()) break;  // load_level reports it
    const BundleLevelInfo& l = manifest_.levels[k];
    const std::uint64_t masked = std::uint64_t(l.masked_apl_count());
    // Each map's texels, and a masked APL's coverage (one channel) beside its map.
    decoded += (std::uint64_t(l.apl_count()) * std::uint64_t(channel_count(manifest_.channels)) + masked) * 2 *
               std::uint64_t(l.map_resolution) * std::uint64_t(l.map_resolution) * sizeof(float);
  }
  if (max_resolution <= 0 && decoded > limits_.max_loaded_bytes)
    fail(path_, "levels", "loading them would take " + std::to_string(decoded) + " bytes, above BundleLimits::max_loaded_bytes (" +
                                 std::to_string(limits_.max_loaded_bytes) + ")");
  AplSet set = empty_set();
  std::size_t previous = std::size_t(-1);
  for (std::size_t k : chosen) {
    if (previous != std::size_t(-1) && k <= previous) fail(path_, "levels", "requested levels must increase");
    AplLevel level = load_level(k, max_resolution);
    // Parent links name the manifest's previous level. When levels in between are skipped, follow the
    // manifest's parent arrays up to the level loaded before (cuts of one tree: the ancestor's flux is
    // still the sum of its descendants'); the first loaded level has none.
    for (Apl& a : level.apls) {
      if (set.levels.empty()) {
        a.parent = -1;
        continue;
      }
      for (std::size_t up = k - 1; up > previous; --up) a.parent = manifest_.levels[up].parent[std::size_t(a.parent)];
    }
    set.levels.push_back(std::move(level));
    previous = k;
  }
  return set;
}

std::string BundleReader::read_attachment(std::size_t index) const {
  if (index >= manifest_.attachments.size())
    fail(path_, "attachments", std::to_string(index) + " does not exist");
  return read_payload(manifest_.attachments[index].second, "/attachments/" + std::to_string(index));
}

namespace {

// A model's payloads as its codec reads them: only those it asks for, each size- and checksum-verified.
class ModelSource final : public ModelPayloadSource {
 public:
  ModelSource(const BundleModelInfo& info, std::size_t index, std::string where,
              std::function<std::string(const BundlePayload&, const std::string&)> read)
      : info_(info), pointer_("/models/" + std::to_string(index)), where_(std::move(where)), read_(std::move(read)) {}
  std::vector<std::string> names() const override {
    std::vector<std::string> n;
    for (const auto& [name, p] : info_.payloads) n.push_back(name);
    return n;
  }
  std::uint64_t size(const std::string& name) const override { return find(name).bytes; }
  std::string read(const std::string& name) const override { return read_(find(name), field_of(name)); }
  const std::string& where() const override { return where_; }

 private:
  std::string field_of(const std::string& name) const {
    for (std::size_t q = 0; q < info_.payloads.size(); ++q)
      if (info_.payloads[q].first == name) return pointer_ + "/payloads/" + std::to_string(q);
    return pointer_ + "/payloads";
  }
  const BundlePayload& find(const std::string& name) const {
    for (const auto& [n, p] : info_.payloads)
      if (n == name) return p;
    throw_at_field(where_, "payloads", "model \"" + info_.name + "\" has no payload \"" + name + "\"");
  }
  const BundleModelInfo& info_;
  std::string pointer_;  // /models/INDEX
  std::string where_;
  std::function<std::string(const BundlePayload&, const std::string&)> read_;
};

}  // namespace

std::unique_ptr<LightModel> BundleReader::load_model(std::size_t index, const ModelLoadOptions& options) const {
  const std::string manifest = join(path_, bundle::kManifestName);
  if (index >= manifest_.models.size()) fail(manifest, "/models", std::to_string(index) + " does not exist");
  const BundleModelInfo& info = manifest_.models[index];
  const std::string at = "/models/" + std::to_string(index);
  const ModelType* t = find_model_type(info.type);
  if (!t || !t->read)
    fail(manifest, at + "/type", "no representation is registered as \"" + info.type + "\" in this program");
  // where(): the manifest and the model's pointer, e.g. bundle/manifest.json#/models/0.
  const ModelSource source(info, index, manifest + "#" + at,
                           [this](const BundlePayload& p, const std::string& field) { return read_payload(p, field); });
  std::unique_ptr<LightModel> model;
  try {
    model = t->read(info.section, source, options);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    fail(manifest, at, "\"" + info.type + "\" could not read it: " + e.what());
  }
  if (!model) fail(manifest, at, "\"" + info.type + "\" read no model");
  if (model->type() != info.type) fail(manifest, at + "/type", "the codec of \"" + info.type + "\" made a \"" + model->type() + "\"");
  return model;
}

std::vector<BundleRepresentation> BundleReader::representations() const {
  std::vector<BundleRepresentation> out;
  for (std::size_t k = 0; k < manifest_.levels.size(); ++k) {
    const BundleLevelInfo& l = manifest_.levels[k];
    BundleRepresentation r;
    r.name = "apl:" + std::to_string(k);
    r.type = "apl";
    r.description = std::to_string(l.apl_count()) + (l.apl_count() == 1 ? " APL" : " APLs") + ", maps R " +
                    std::to_string(l.map_resolution);
    if (const std::size_t masked = l.masked_apl_count(); masked > 0) r.description += ", " + std::to_string(masked) + " masked";
    r.bytes = l.maps.empty() ? 0 : l.maps.front().bytes;
    r.level = int(k);
    out.push_back(std::move(r));
  }
  for (std::size_t i = 0; i < manifest_.models.size(); ++i) {
    const BundleModelInfo& m = manifest_.models[i];
    BundleRepresentation r;
    r.name = m.name;
    r.type = m.type;
    const ModelType* t = find_model_type(m.type);
    r.description = t ? t->description : "(type not registered in this program)";
    r.bytes = m.payload_bytes();
    r.model = int(i);
    out.push_back(std::move(r));
  }
  return out;
}

std::unique_ptr<LightModel> BundleReader::load_representation(std::size_t index, const ModelLoadOptions& options) const {
  const std::vector<BundleRepresentation> all = representations();
  if (index >= all.size())
    fail(join(path_, bundle::kManifestName), "representation", std::to_string(index) + " does not exist (" +
                                                                   std::to_string(all.size()) + " listed)");
  const BundleRepresentation& r = all[index];
  if (r.model >= 0) return load_model(std::size_t(r.model), options);
  auto set = std::make_shared<AplSet>(empty_set());
  set->levels.push_back(load_level(std::size_t(r.level), options.max_resolution));
  return std::make_unique<AplLevelModel>(std::move(set), 0);
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
  for (std::size_t i = 0; i < m.attachments.size(); ++i) {
    try {
      reader->read_attachment(i);
    } catch (const Error& e) {
      out.push_back(e.diagnostic());
    }
  }
  // Every model through its codec (which reads and verifies its payloads), then any payload it left unread.
  for (std::size_t i = 0; i < m.models.size(); ++i) {
    try {
      reader->load_model(i);
      for (std::size_t q = 0; q < m.models[i].payloads.size(); ++q)
        reader->read_payload(m.models[i].payloads[q].second, "/models/" + std::to_string(i) + "/payloads/" + std::to_string(q));
    } catch (const Error& e) {
      out.push_back(e.diagnostic());
    } catch (const std::exception& e) {
      note(join(path, bundle::kManifestName), "/models/" + std::to_string(i), e.what());
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
