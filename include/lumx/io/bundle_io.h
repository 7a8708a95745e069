// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/io/bundle_io.h — the lumx bundle: an APL set (and optionally a radiance volume) on disk.
//
// A bundle is a folder:
//   manifest.json                  what is inside, validated by schema/bundle-manifest.schema.json
//   levels/level01_n00008_r0256.exr  one OpenEXR image per (level index, APL count, map resolution): the
//   levels/level01_n00008_r0128.exr  level's maps stacked vertically (APL i occupies rows [i·R, (i+1)·R)),
//                                    then the same maps
//   ...                            box-filtered to R/2, R/4, ... (flux-exact, see SphereMap::downsampled)
//   volume.exr                     the radiance volume's SH coefficients (float), if any
//   attachments/NAME               files shipped with the set, e.g. its far field as IES and EULUMDAT
//   models/NAME/PAYLOAD            the payloads of further representations (model/registry.h): each a
//                                  manifest section written by its type's codec, and named payloads
// Every payload's size and SHA-256 are in the manifest; maps are half floats unless a value exceeds half's
// range (65504) or the peak is so small that half would lose precision, in which case that payload is
// float — never a silent Inf (hard-cases §3).
//
// Loading is partial by design ("a scene loads only what it needs"): BundleReader reads the manifest
// alone; load_level() reads one level's payload at the largest stored resolution not above the caller's
// limit (the coarsest stored one if none is), so a distant luminaire reads a few kilobytes. Every payload is size- and checksum-verified before
// OpenEXR parses it, and every count is checked against limits before anything is allocated.
//
// Writing is atomic at the folder level: the bundle is assembled in a temporary sibling folder, then
// swapped in with one rename (renameat2 RENAME_EXCHANGE when a bundle already exists), so a failed write
// leaves the previous bundle as it was.
#pragma once

#include <lumx/apl/apl_set.h>
#include <lumx/core/diagnostic.h>
#include <lumx/math/spherical_harmonics.h>
#include <lumx/model/light_model.h>
#include <lumx/model/registry.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

class RadianceVolume;

namespace bundle {
inline constexpr int kFormatVersion = 4;
/// The oldest format version this lumx reads. Version 2 added a level's optional "map_frame"; a version 1
/// bundle's maps are in the photometric frame. Version 3 added the optional "masks" (beam masks of point
/// sources behind apertures) and a level's "mask"; a set without masks is still written as version 2, so
/// that earlier readers read it. Version 4 added "models" (representations by registered type); a bundle
/// without them is written as version 2 or 3 as before.
inline constexpr int kOldestFormatVersion = 1;
inline constexpr const char* kFormatName = "lumx-bundle";
inline constexpr const char* kManifestName = "manifest.json";
}  // namespace bundle

/// One payload file named by the manifest.
struct BundlePayload {
  std::string file;           ///< path relative to the bundle folder, '/'-separated
  std::uint64_t bytes = 0;    ///< exact file size
  std::string sha256;         ///< lowercase hex digest of the file
  std::string pixel_type;     ///< "half" or "float"
  int resolution = 0;         ///< map resolution R of this payload (maps only)
};

/// A file shipped inside the bundle (attachments/NAME), checksummed like every payload.
struct BundleAttachment {
  std::string name;        ///< file name: letters, digits, '.', '_' and '-' only
  std::string media_type;  ///< e.g. "application/x-ies-lm63", "application/x-eulumdat"
  std::string bytes;       ///< contents (writing); empty after reading the manifest
};

struct BundleLevelInfo {
  int map_resolution = 0;              ///< full resolution R of this level's maps
  MapFrame frame;                      ///< the frame the maps are drawn in (identity when not stored)
  std::vector<glm::vec3> position;     ///< m, one per APL
  std::vector<glm::dvec3> flux;        ///< lm or W per channel, one per APL
  std::vector<int> parent;             ///< index in the previous level, −1 in the first
  std::vector<int> mask;               ///< per APL: index in BundleManifest::masks, −1 none; empty: none masked
  std::vector<BundlePayload> maps;     ///< decreasing resolution; maps[0] is full resolution
  ErrorTable error;
  std::size_t apl_count() const { return position.size(); }
  /// APLs with a beam mask (each also holds its coverage in memory when loaded: one float a texel).
  std::size_t masked_apl_count() const {
    return std::size_t(std::count_if(mask.begin(), mask.end(), [](int i) { return i >= 0; }));
  }
};

/// A representation stored by its registered type's codec (model/registry.h).
struct BundleModelInfo {
  std::string name;     ///< unique in the bundle: 1–128 of [A-Za-z0-9._-]
  std::string type;     ///< the registered type name
  std::string section;  ///< the codec's section, as the text of one JSON object
  /// Payload name → file (models/NAME/PAYLOAD), size and checksum; in the order the codec added them.
  std::vector<std::pair<std::string, BundlePayload>> payloads;
  std::uint64_t payload_bytes() const {
    std::uint64_t b = 0;
    for (const auto& [n, p] : payloads) b += p.bytes;
    return b;
  }
};

struct BundleVolumeInfo {
  glm::dvec3 lo{0.0}, hi{0.0};  ///< grid bounds, m
  glm::ivec3 counts{0};         ///< voxels per axis
  double voxel_size = 0;        ///< m (cubic voxels)
  int bands = 0;                ///< SH bands (coefficients = bands²)
  int channels = 0;             ///< 1 or 3
  sh::Window window = sh::Window::vallee_poussin;  ///< applied when evaluating (anti-ringing)
  BundlePayload payload;
};

/// The manifest as read, after validation.
struct BundleManifest {
  int format_version = bundle::kFormatVersion;
  std::string generator;
  PhotometricQuantity quantity = PhotometricQuantity::photometric;
  ChannelLayout channels = ChannelLayout::luminance;
  BoundingSphere bounds;
  std::map<std::string, std::string> provenance;
  std::vector<BundleLevelInfo> levels;
  /// The masks APLs refer to (apl_set.h, math/direction_mask.h), each stored once: caps as chart axis,
  /// tangent basis and hull vertices, in the photometric frame.
  std::vector<std::shared_ptr<const DirectionMask>> masks;
  std::optional<BundleVolumeInfo> volume;
  std::vector<std::pair<BundleAttachment, BundlePayload>> attachments;  ///< name/type and file/bytes/sha256
  std::vector<BundleModelInfo> models;  ///< further representations, by registered type
  std::uint64_t manifest_bytes = 0;

  /// Bytes of every payload plus the manifest: what a full load reads.
  std::uint64_t total_bytes() const;
};

enum class MapPixelType { automatic, half, float32 };

struct BundleWriteOptions {
  /// automatic: half when a payload's largest value is in [2^-4, 65504] (so values down to 2^-10 of the
  /// peak keep half's full 11-bit precision), float otherwise. `half` refuses (throws) rather than
  /// overflow to Inf.
  MapPixelType pixel_type = MapPixelType::automatic;
  /// Store box-filtered copies of each level down to this resolution (0: full resolution only).
  int min_stored_resolution = 8;
  /// Files to ship in attachments/ (names must be unique).
  std::vector<BundleAttachment> attachments;
  /// Further representations, each written by the codec of its type() (which must be registered and
  /// write sections); names unique, 1–128 of [A-Za-z0-9._-].
  std::vector<std::pair<std::string, std::shared_ptr<const LightModel>>> models;
};

/// One representation a bundle holds, as BundleReader::representations() lists them.
struct BundleRepresentation {
  std::string name;         ///< "apl:K" for APL level K; a model's own name
  std::string type;         ///< registered type name
  std::string description;  ///< from the manifest alone (no payload read)
  std::uint64_t bytes = 0;  ///< bytes on disk a full load reads
  int level = -1;           ///< the APL level, or −1
  int model = -1;           ///< index in BundleManifest::models, or −1
};

/// Writes `set` (and `volume`, if given) as a bundle folder at `path`, replacing an existing bundle
/// atomically. Refuses to replace a folder that is not a bundle (no manifest.json). Throws lumx::Error.
void write_bundle(const std::string& path, const AplSet& set, const RadianceVolume* volume = nullptr,
                  const BundleWriteOptions& options = {});

/// Upper bounds on what a reader accepts, checked before any allocation.
struct BundleLimits {
  std::uint64_t max_manifest_bytes = 64ull << 20;
  std::uint64_t max_payload_bytes = 4ull << 30;
  std::size_t max_levels = 64;
  std::size_t max_apls_per_level = 1u << 20;
  std::size_t max_masks = 4096;             ///< beam masks in a manifest
  std::size_t max_models = 64;              ///< entries of "models"
  std::size_t max_model_payloads = 1024;    ///< payloads of one model
  std::size_t max_caps_per_mask = kMaxMaskCaps;            ///< caps in one mask (256)
  std::size_t max_hull_vertices = kMaxMaskHullVertices;    ///< vertices of one cap's hull (4 096)
  /// The reader computes each masked APL's coverage (mask_coverage_subsamples(R)² sub-directions a texel, each tested against
  /// every cap in O(log vertices)); a manifest whose masks would take more tests than this over its
  /// levels at their full resolutions is refused (2^31: a few seconds), so a hostile manifest cannot make loading hang.
  std::uint64_t max_mask_tests = std::uint64_t(kMaxMaskTests);
  /// Largest decoded size of one payload in memory (float texels or coefficients). A compressed payload
  /// of a few megabytes can decode to gigabytes, so this bounds memory, not file size.
  std::uint64_t max_decoded_bytes = 2ull << 30;
  /// Largest total decoded size of one BundleReader::load() at full resolution.
  std::uint64_t max_loaded_bytes = 8ull << 30;
};

std::vector<Diagnostic> check_bundle(const std::string& path, double flux_tolerance);

/// Opens a bundle and reads its manifest only; levels and the volume are loaded on request.
class BundleReader {
 public:
  /// Keeps the folder open: every later load reads from the folder opened here, never through a
  /// symbolic link, even if the path is renamed or re-pointed meanwhile.
  explicit BundleReader(const std::string& path, const BundleLimits& limits = {});
  ~BundleReader();
  BundleReader(BundleReader&& other) noexcept;
  BundleReader(const BundleReader&) = delete;
  BundleReader& operator=(const BundleReader&) = delete;
  BundleReader& operator=(BundleReader&&) = delete;

  const BundleManifest& manifest() const { return manifest_; }
  const std::string& path() const { return path_; }

  /// The set's metadata (units, channels, bounds, provenance) with no levels.
  AplSet empty_set() const;
  /// One level's APLs with maps at the largest stored resolution ≤ max_resolution (0 = full; the
  /// coarsest stored resolution when max_resolution is below it).
  AplLevel load_level(std::size_t level, int max_resolution = 0) const;
  /// The set with the chosen levels (all if empty, increasing), each at most max_resolution. When levels
  /// are skipped, parents are re-linked to their ancestor in the previous loaded level (the manifest keeps
  /// every level's parent array), so the result is still a valid tree.
  AplSet load(const std::vector<std::size_t>& levels = {}, int max_resolution = 0) const;
  bool has_volume() const { return manifest_.volume.has_value(); }
  RadianceVolume load_volume() const;
  /// The contents of attachment `index` (checksum verified).
  std::string read_attachment(std::size_t index) const;

  /// Model `index` of the manifest's "models", read by its type's codec, which reads only the payloads it
  /// needs (checksum verified). Throws lumx::Error naming /models/INDEX when its type is not registered
  /// in this process or its section or payloads are malformed.
  std::unique_ptr<LightModel> load_model(std::size_t index, const ModelLoadOptions& options = {}) const;
  /// Every representation the bundle holds, whatever its type: each APL level ("apl"), then the models.
  std::vector<BundleRepresentation> representations() const;
  /// Representation `index` of representations(); an APL level is loaded at options.max_resolution.
  std::unique_ptr<LightModel> load_representation(std::size_t index, const ModelLoadOptions& options = {}) const;

  /// Bytes read from disk through this reader so far (manifest included).
  std::uint64_t bytes_read() const { return bytes_read_; }

 private:
  friend std::vector<Diagnostic> check_bundle(const std::string& path, double flux_tolerance);
  std::string read_payload(const BundlePayload& p, const std::string& field) const;

  std::string path_;
  BundleLimits limits_;
  BundleManifest manifest_;
  mutable std::uint64_t bytes_read_ = 0;
  int folder_fd_ = -1;
};

/// Findings of a full check: every payload read, checksums, the set's consistency (check_apl_set),
/// flux equal across levels, maps non-negative and finite. Empty = OK. Never throws for bad content.
std::vector<Diagnostic> check_bundle(const std::string& path, double flux_tolerance = 1e-3);

LUMX_NAMESPACE_END
