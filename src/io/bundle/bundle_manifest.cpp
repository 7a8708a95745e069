// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/io/bundle/bundle_manifest.cpp — manifest serialisation and validating parser.
#include "io/bundle/bundle_manifest.h"
#include "io/json_depth.h"
#include "io/json_members.h"

#include <lumx/math/sphere_map.h>

#include <nlohmann/json.hpp>

#include <cctype>
#include <cmath>
#include <set>

LUMX_NAMESPACE_BEGIN
namespace detail {

using nlohmann::json;

bool is_json_object_text(const std::string& text) {
  if (detail::json_too_deep_at(text) != std::string_view::npos) return false;
  const json j = json::parse(text, nullptr, false);
  return !j.is_discarded() && j.is_object();
}

bool is_attachment_name(const std::string& name) {
  if (name.empty() || name.size() > 128 || name == "." || name == "..") return false;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') return false;
  return true;
}

std::vector<std::string> map_channel_names(ChannelLayout layout) {
  return layout == ChannelLayout::rgb ? std::vector<std::string>{"R", "G", "B"} : std::vector<std::string>{"Y"};
}

std::vector<std::string> volume_channel_names(int channels, int bands) {
  static const char* rgb[] = {"R", "G", "B"};
  std::vector<std::string> names;
  for (int c = 0; c < channels; ++c)
    for (int k = 0; k < bands * bands; ++k) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "sh%02d.%s", k, channels == 1 ? "Y" : rgb[c]);
      names.push_back(buf);
    }
  return names;
}

namespace {

const char* window_name(sh::Window w) {
  switch (w) {
    case sh::Window::none: return "none";
    case sh::Window::lanczos: return "lanczos";
    case sh::Window::hann: return "hann";
    case sh::Window::vallee_poussin: return "vallee_poussin";
  }
  return "none";
}

json vec3_json(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }

json payload_json(const BundlePayload& p, bool with_resolution) {
  json j = {{"file", p.file}, {"bytes", p.bytes}, {"sha256", p.sha256}, {"pixel_type", p.pixel_type}};
  if (with_resolution) j["resolution"] = p.resolution;
  return j;
}

// ---- parsing: every accessor names the JSON pointer of what it reads ----
class Reader {
 public:
  Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
    throw_at_field(file_, pointer.empty() ? "/" : pointer, message);
  }
  const json& member(const json& obj, const std::string& pointer, const char* key) const {
    if (!obj.is_object()) fail(pointer, "expected an object");
    auto it = obj.find(key);
    if (it == obj.end()) fail(pointer + "/" + key, "missing");
    return *it;
  }
  /// The schema's additionalProperties: false — a member the format does not define is an error
  /// (a misspelt optional member would otherwise be silently ignored).
  void only(const json& obj, const std::string& pointer, std::initializer_list<const char*> keys) const {
    if (!obj.is_object()) fail(pointer, "expected an object");
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      bool known = false;
      for (const char* k : keys) known = known || it.key() == k;
      if (!known) fail(pointer + "/" + it.key(), "is not a member the format defines");
    }
  }
  const json* optional_member(const json& obj, const char* key) const {
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
  double number(const json& j, const std::string& pointer) const {
    if (!j.is_number()) fail(pointer, "expected a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(pointer, "not finite");
    return v;
  }
  /// `limit_name` names the BundleLimits member `hi` comes from, if it does.
  long long integer(const json& j, const std::string& pointer, long long lo, long long hi,
                    const char* limit_name = nullptr) const {
    if (!j.is_number_integer() && !j.is_number_unsigned()) fail(pointer, "expected an integer");
    const std::string bound = limit_name ? std::string(limit_name) + " (" + std::to_string(hi) + ")" : std::to_string(hi);
    if (j.is_number_unsigned() && j.get<unsigned long long>() > (unsigned long long)hi)
      fail(pointer, std::to_string(j.get<unsigned long long>()) + " exceeds " + bound);
    const long long v = j.get<long long>();
    if (v > hi) fail(pointer, std::to_string(v) + " exceeds " + bound);
    if (v < lo) fail(pointer, std::to_string(v) + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }
  std::string string(const json& j, const std::string& pointer) const {
    if (!j.is_string()) fail(pointer, "expected a string");
    return j.get<std::string>();
  }
  const json& array(const json& j, const std::string& pointer, std::size_t expected_size) const {
    if (!j.is_array()) fail(pointer, "expected an array");
    if (expected_size != std::size_t(-1) && j.size() != expected_size)
      fail(pointer, "has " + std::to_string(j.size()) + " entries, expected " + std::to_string(expected_size));
    return j;
  }
  glm::dvec3 vec3(const json& j, const std::string& pointer) const {
    array(j, pointer, 3);
    return {number(j[0], pointer + "/0"), number(j[1], pointer + "/1"), number(j[2], pointer + "/2")};
  }
  BundlePayload payload(const json& j, const std::string& pointer, const BundleLimits& limits) const {
    BundlePayload p;
    p.file = string(member(j, pointer, "file"), pointer + "/file");
    // Payloads live inside the bundle: relative, no "..", no backslashes or absolute paths.
    if (p.file.empty() || p.file.front() == '/' || p.file.find('\\') != std::string::npos ||
        p.file.find("..") != std::string::npos || p.file.find('\0') != std::string::npos)
      fail(pointer + "/file", "\"" + p.file + "\" is not a relative path inside the bundle");
    p.bytes = std::uint64_t(integer(member(j, pointer, "bytes"), pointer + "/bytes", 1, (long long)limits.max_payload_bytes,
                                   "BundleLimits::max_payload_bytes"));
    p.sha256 = string(member(j, pointer, "sha256"), pointer + "/sha256");
    if (p.sha256.size() != 64 || p.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
      fail(pointer + "/sha256", "not 64 lowercase hexadecimal digits");
    p.pixel_type = string(member(j, pointer, "pixel_type"), pointer + "/pixel_type");
    if (p.pixel_type != "half" && p.pixel_type != "float") fail(pointer + "/pixel_type", "must be \"half\" or \"float\"");
    return p;
  }

 private:
  std::string file_;
};

}  // namespace

std::string manifest_to_json(const BundleManifest& m) {
  json j;
  j["format"] = bundle::kFormatName;
  j["format_version"] = m.format_version;
  j["generator"] = m.generator;
  j["units"] = {{"length", "m"},
                {"intensity", intensity_unit(m.quantity)},
                {"flux", flux_unit(m.quantity)},
                {"irradiance", irradiance_unit(m.quantity)}};
  j["channels"] = map_channel_names(m.channels);
  j["bounding_sphere"] = {{"center", vec3_json(m.bounds.center)}, {"radius", m.bounds.radius}};
  j["provenance"] = json::object();
  for (const auto& [k, v] : m.provenance) j["provenance"][k] = v;
  const int nc = channel_count(m.channels);
  j["levels"] = json::array();
  for (const BundleLevelInfo& l : m.levels) {
    json level;
    level["apl_count"] = l.apl_count();
    level["map_resolution"] = l.map_resolution;
    if (!l.frame.is_identity()) {  // rows: the map's axes in the photometric frame
      json rows = json::array();
      for (int r = 0; r < 3; ++r) {
        const glm::vec3 row = l.frame.row(r);
        rows.push_back(json::array({double(row.x), double(row.y), double(row.z)}));
      }
      level["map_frame"] = rows;
    }
    json pos = json::array(), flux = json::array();
    for (const glm::vec3& p : l.position) pos.push_back(json::array({p.x, p.y, p.z}));
    for (const glm::dvec3& f : l.flux) {
      json row = json::array();
      for (int c = 0; c < nc; ++c) row.push_back(f[c]);
      flux.push_back(row);
    }
    level["position"] = pos;
    level["flux"] = flux;
    level["parent"] = l.parent;
    if (!l.mask.empty()) level["mask"] = l.mask;
    level["maps"] = json::array();
    for (const BundlePayload& p : l.maps) level["maps"].push_back(payload_json(p, true));
    if (!l.error.empty())
      level["error_vs_distance"] = {{"relative_distance", l.error.relative_distance},
                                    {"relative_rmse", l.error.relative_rmse}};
    j["levels"].push_back(level);
  }
  if (!m.masks.empty()) {
    j["masks"] = json::array();
    for (const std::shared_ptr<const DirectionMask>& mask : m.masks) {
      json caps = json::array();
      for (const DirectionMask::Cap& c : mask->caps()) {
        json hull = json::array();
        for (const glm::dvec2& v : c.hull) hull.push_back(json::array({v.x, v.y}));
        caps.push_back({{"axis", vec3_json(c.axis)}, {"e1", vec3_json(c.e1)}, {"e2", vec3_json(c.e2)}, {"hull", hull}});
      }
      j["masks"].push_back({{"caps", caps}});
    }
  }
  if (!m.attachments.empty()) {
    j["attachments"] = json::array();
    for (const auto& [a, p] : m.attachments)
      j["attachments"].push_back(
          {{"file", p.file}, {"bytes", p.bytes}, {"sha256", p.sha256}, {"media_type", a.media_type}});
  }
  if (!m.models.empty()) {
    j["models"] = json::array();
    for (const BundleModelInfo& model : m.models) {
      json payloads = json::array();
      for (const auto& [name, p] : model.payloads)
        payloads.push_back({{"name", name}, {"file", p.file}, {"bytes", p.bytes}, {"sha256", p.sha256}});
      j["models"].push_back({{"name", model.name}, {"type", model.type}, {"section", json::parse(model.section)},
                             {"payloads", payloads}});
    }
  }
  if (m.volume) {
    const BundleVolumeInfo& v = *m.volume;
    json vol = payload_json(v.payload, false);
    vol["bounds"] = {{"min", vec3_json(v.lo)}, {"max", vec3_json(v.hi)}};
    vol["counts"] = json::array({v.counts.x, v.counts.y, v.counts.z});
    vol["voxel_size"] = v.voxel_size;
    vol["sh_bands"] = v.bands;
    vol["channels"] = v.channels;
    vol["window"] = window_name(v.window);
    vol["radiance_unit"] = m.quantity == PhotometricQuantity::photometric ? "cd/m^2" : "W/(m^2 sr)";
    j["volume"] = vol;
  }
  return j.dump(1) + "\n";
}

BundleManifest parse_manifest(std::string_view text, const std::string& file, const BundleLimits& limits) {
  Reader r(file);
  json j;
  if (const std::size_t at = detail::json_too_deep_at(text); at != std::string_view::npos) {
    Diagnostic d;
    d.file = file;
    d.byte_offset = std::int64_t(at);
    d.field = "JSON";
    d.message = "nested more than " + std::to_string(detail::kMaxJsonDepth) + " levels deep";
    throw Error(std::move(d));
  }
  detail::RepeatedMemberWatch<json> members;
  try {
    j = json::parse(text.begin(), text.end(), members.callback());
  } catch (const json::parse_error& e) {
    Diagnostic d;
    d.file = file;
    d.byte_offset = std::int64_t(e.byte);
    d.field = "JSON";
    d.message = e.what();
    throw Error(std::move(d));
  } catch (const json::exception& e) {  // a number beyond double's range (out_of_range 406): no position given
    const std::size_t at = e.id == 406 ? detail::json_overflow_at(text, e.what()) : std::string_view::npos;
    if (at == std::string_view::npos) r.fail("", std::string("not valid JSON for a manifest: ") + e.what());
    Diagnostic d;
    d.file = file;
    d.byte_offset = std::int64_t(at);
    d.field = "JSON";
    d.message = "a number beyond the range of a double";
    throw Error(std::move(d));
  }
  if (!members.repeated().empty())
    r.fail(members.repeated(), "this name appears twice in its object; readers disagree on which value counts");
  if (!j.is_object()) r.fail("", "the manifest is not a JSON object");
  r.only(j, "", {"format", "format_version", "generator", "units", "channels", "bounding_sphere", "provenance",
                 "levels", "masks", "volume", "attachments", "models"});
  BundleManifest m;
  m.manifest_bytes = text.size();
  if (r.string(r.member(j, "", "format"), "/format") != bundle::kFormatName)
    r.fail("/format", std::string("not \"") + bundle::kFormatName + "\"");
  m.format_version = int(r.integer(r.member(j, "", "format_version"), "/format_version", 1, 1 << 20));
  if (m.format_version < bundle::kOldestFormatVersion || m.format_version > bundle::kFormatVersion)
    r.fail("/format_version", "version " + std::to_string(m.format_version) + " is not supported (this lumx reads " +
                                  std::to_string(bundle::kOldestFormatVersion) + " to " +
                                  std::to_string(bundle::kFormatVersion) + ")");
  m.generator = r.string(r.member(j, "", "generator"), "/generator");

  const json& units = r.member(j, "", "units");
  r.only(units, "/units", {"length", "intensity", "flux", "irradiance"});
  const std::string length = r.string(r.member(units, "/units", "length"), "/units/length");
  if (length != "m") r.fail("/units/length", "must be \"m\"");
  const std::string intensity = r.string(r.member(units, "/units", "intensity"), "/units/intensity");
  if (intensity == "cd") m.quantity = PhotometricQuantity::photometric;
  else if (intensity == "W/sr") m.quantity = PhotometricQuantity::radiometric;
  else r.fail("/units/intensity", "must be \"cd\" or \"W/sr\"");
  if (r.string(r.member(units, "/units", "flux"), "/units/flux") != flux_unit(m.quantity))
    r.fail("/units/flux", std::string("must be \"") + flux_unit(m.quantity) + "\" with intensity in " + intensity);
  if (r.string(r.member(units, "/units", "irradiance"), "/units/irradiance") != irradiance_unit(m.quantity))
    r.fail("/units/irradiance", std::string("must be \"") + irradiance_unit(m.quantity) + "\"");

  const json& ch = r.array(r.member(j, "", "channels"), "/channels", std::size_t(-1));
  if (ch == json::array({"Y"})) m.channels = ChannelLayout::luminance;
  else if (ch == json::array({"R", "G", "B"})) m.channels = ChannelLayout::rgb;
  else r.fail("/channels", "must be [\"Y\"] or [\"R\", \"G\", \"B\"]");
  const int nc = channel_count(m.channels);

  const json& bs = r.member(j, "", "bounding_sphere");
  r.only(bs, "/bounding_sphere", {"center", "radius"});
  m.bounds.center = r.vec3(r.member(bs, "/bounding_sphere", "center"), "/bounding_sphere/center");
  m.bounds.radius = r.number(r.member(bs, "/bounding_sphere", "radius"), "/bounding_sphere/radius");
  if (m.bounds.radius < 0) r.fail("/bounding_sphere/radius", "negative");

  if (const json* prov = r.optional_member(j, "provenance")) {
    if (!prov->is_object()) r.fail("/provenance", "expected an object");
    for (auto it = prov->begin(); it != prov->end(); ++it)
      m.provenance[it.key()] = r.string(it.value(), "/provenance/" + it.key());
  }

  // Masks before the levels that refer to them (a JSON object's members have no order).
  if (const json* mj = r.optional_member(j, "masks")) {
    if (m.format_version < 3) r.fail("/masks", "not part of format version " + std::to_string(m.format_version));
    const json& list = r.array(*mj, "/masks", std::size_t(-1));
    if (list.empty() || list.size() > limits.max_masks)
      r.fail("/masks", std::to_string(list.size()) + " masks: 1 to BundleLimits::max_masks (" + std::to_string(limits.max_masks) + ")");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string at = "/masks/" + std::to_string(i);
      r.only(list[i], at, {"caps"});
      const json& caps = r.array(r.member(list[i], at, "caps"), at + "/caps", std::size_t(-1));
      if (caps.empty() || caps.size() > limits.max_caps_per_mask)
        r.fail(at + "/caps", std::to_string(caps.size()) + " caps: 1 to BundleLimits::max_caps_per_mask (" +
                                 std::to_string(limits.max_caps_per_mask) + ")");
      std::vector<DirectionMask::Cap> out(caps.size());
      for (std::size_t c = 0; c < caps.size(); ++c) {
        const std::string cp = at + "/caps/" + std::to_string(c);
        r.only(caps[c], cp, {"axis", "e1", "e2", "hull"});
        out[c].axis = r.vec3(r.member(caps[c], cp, "axis"), cp + "/axis");
        out[c].e1 = r.vec3(r.member(caps[c], cp, "e1"), cp + "/e1");
        out[c].e2 = r.vec3(r.member(caps[c], cp, "e2"), cp + "/e2");
        const json& hull = r.array(r.member(caps[c], cp, "hull"), cp + "/hull", std::size_t(-1));
        if (hull.size() < 3 || hull.size() > limits.max_hull_vertices)
          r.fail(cp + "/hull", std::to_string(hull.size()) + " vertices: 3 to BundleLimits::max_hull_vertices (" +
                                   std::to_string(limits.max_hull_vertices) + ")");
        out[c].hull.reserve(hull.size());
        for (std::size_t v = 0; v < hull.size(); ++v) {
          const std::string vp = cp + "/hull/" + std::to_string(v);
          const json& xy = r.array(hull[v], vp, 2);
          out[c].hull.push_back({r.number(xy[0], vp + "/0"), r.number(xy[1], vp + "/1")});
        }
      }
      for (std::size_t c = 0; c < out.size(); ++c) {  // each cap alone first, for its pointer
        try {
          (void)DirectionMask::from_caps({out[c]});
        } catch (const std::invalid_argument& e) {
          r.fail(at + "/caps/" + std::to_string(c), std::string(e.what()).substr(std::string("cap 0: ").size()));
        }
      }
      m.masks.push_back(std::make_shared<const DirectionMask>(DirectionMask::from_caps(std::move(out))));
    }
  }

  const json& levels = r.array(r.member(j, "", "levels"), "/levels", std::size_t(-1));
  if (levels.empty()) r.fail("/levels", "no level");
  if (levels.size() > limits.max_levels) r.fail("/levels", std::to_string(levels.size()) + " levels exceed BundleLimits::max_levels (" +
                                                                    std::to_string(limits.max_levels) + ")");
  std::set<std::string> files;
  double mask_tests = 0;  // the masks' coverage work, over every level (BundleLimits::max_mask_tests)
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const std::string at = "/levels/" + std::to_string(k);
    const json& lj = levels[k];
    r.only(lj, at, {"apl_count", "map_resolution", "map_frame", "position", "flux", "parent", "mask", "maps",
                    "error_vs_distance"});
    BundleLevelInfo l;
    const std::size_t n = std::size_t(r.integer(r.member(lj, at, "apl_count"), at + "/apl_count", 1,
                                                (long long)limits.max_apls_per_level, "BundleLimits::max_apls_per_level"));
    if (k > 0 && n <= m.levels.back().apl_count())
      r.fail(at + "/apl_count", "does not exceed the previous level's " + std::to_string(m.levels.back().apl_count()));
    l.map_resolution = int(r.integer(r.member(lj, at, "map_resolution"), at + "/map_resolution", 1, sphere_map::kMaxResolution));
    if (lj.contains("map_frame")) {
      const std::string fp = at + "/map_frame";
      if (m.format_version < 2) r.fail(fp, "not part of format version " + std::to_string(m.format_version));
      const json& rows = r.array(lj["map_frame"], fp, 3);
      for (int row = 0; row < 3; ++row) {
        const std::string rp = fp + "/" + std::to_string(row);
        const glm::dvec3 v = r.vec3(rows[std::size_t(row)], rp);
        for (int c = 0; c < 3; ++c) {
          // A rotation's entries lie in [−1, 1]; checked before the cast to float, which a larger value
          // would overflow.
          if (!(std::abs(v[c]) <= 1.0 + 1e-3)) r.fail(rp + "/" + std::to_string(c), "outside [-1, 1]: not a rotation");
          l.frame.to_map[c][row] = float(v[c]);
        }
      }
      const auto [off, det] = l.frame.deviation();
      if (!(off <= 1e-4f) || !(std::abs(det - 1.0f) <= 1e-4f))
        r.fail(fp, "not a rotation: |RᵀR − I| is " + std::to_string(off) + ", the determinant " + std::to_string(det));
    }
    const json& pos = r.array(r.member(lj, at, "position"), at + "/position", n);
    const json& flux = r.array(r.member(lj, at, "flux"), at + "/flux", n);
    const json& parent = r.array(r.member(lj, at, "parent"), at + "/parent", n);
    l.position.reserve(n);
    l.flux.reserve(n);
    l.parent.reserve(n);
    const long long parent_max = k == 0 ? -1 : (long long)m.levels.back().apl_count() - 1;
    for (std::size_t i = 0; i < n; ++i) {
      const std::string is = std::to_string(i);
      l.position.push_back(glm::vec3(r.vec3(pos[i], at + "/position/" + is)));
      const json& f = r.array(flux[i], at + "/flux/" + is, std::size_t(nc));
      glm::dvec3 fv(0.0);
      for (int c = 0; c < nc; ++c) {
        fv[c] = r.number(f[c], at + "/flux/" + is + "/" + std::to_string(c));
        if (fv[c] < 0) r.fail(at + "/flux/" + is + "/" + std::to_string(c), "negative flux");
      }
      if (nc == 1) fv = glm::dvec3(fv.x);
      l.flux.push_back(fv);
      l.parent.push_back(int(r.integer(parent[i], at + "/parent/" + is, k == 0 ? -1 : 0, parent_max)));
    }
    if (const json* mk = r.optional_member(lj, "mask")) {
      const json& list = r.array(*mk, at + "/mask", n);
      for (std::size_t i = 0; i < n; ++i)
        l.mask.push_back(int(r.integer(list[i], at + "/mask/" + std::to_string(i), -1, (long long)m.masks.size() - 1)));
      // The coverage's cost at full resolution, summed over the manifest: each distinct mask once per
      // level (refresh_coverages shares it between the APLs of one source), and a copy of its coverage
      // per masked APL.
      std::set<int> distinct(l.mask.begin(), l.mask.end());
      for (int q : distinct)
        if (q >= 0) mask_tests += m.masks[std::size_t(q)]->coverage_tests(l.map_resolution, mask_coverage_subsamples(l.map_resolution));
      for (int q : l.mask)
        if (q >= 0) mask_tests += 2.0 * l.map_resolution * l.map_resolution;
      if (mask_tests > double(limits.max_mask_tests))
        r.fail(at + "/mask", "the masks' coverage up to this level at R " + std::to_string(l.map_resolution) +
                                 " would take " + std::to_string(mask_tests) +
                                 " tests, above BundleLimits::max_mask_tests (" + std::to_string(limits.max_mask_tests) + ")");
    }
    const json& maps = r.array(r.member(lj, at, "maps"), at + "/maps", std::size_t(-1));
    if (maps.empty() || maps.size() > 16) r.fail(at + "/maps", "must list 1 to 16 payloads");
    for (std::size_t p = 0; p < maps.size(); ++p) {
      const std::string mp = at + "/maps/" + std::to_string(p);
      r.only(maps[p], mp, {"file", "bytes", "sha256", "pixel_type", "resolution"});
      BundlePayload payload = r.payload(maps[p], mp, limits);
      payload.resolution = int(r.integer(r.member(maps[p], mp, "resolution"), mp + "/resolution", 1, sphere_map::kMaxResolution));
      const int expected = p == 0 ? l.map_resolution : l.maps.back().resolution / 2;
      if (payload.resolution != expected || (p > 0 && l.maps.back().resolution % 2 != 0))
        r.fail(mp + "/resolution", std::to_string(payload.resolution) + " is not " + std::to_string(expected) +
                                       " (full resolution first, then halvings)");
      if (!files.insert(payload.file).second) r.fail(mp + "/file", "\"" + payload.file + "\" is listed twice");
      const std::uint64_t decoded = std::uint64_t(n) * 2 * std::uint64_t(payload.resolution) * payload.resolution * nc * 4;
      if (decoded > limits.max_decoded_bytes)
        r.fail(mp, "would decode to " + std::to_string(decoded) + " bytes, above BundleLimits::max_decoded_bytes (" +
                       std::to_string(limits.max_decoded_bytes) + ")");
      l.maps.push_back(payload);
    }
    if (const json* e = r.optional_member(lj, "error_vs_distance")) {
      const std::string ep = at + "/error_vs_distance";
      r.only(*e, ep, {"relative_distance", "relative_rmse"});
      const json& ds = r.array(r.member(*e, ep, "relative_distance"), ep + "/relative_distance", std::size_t(-1));
      const json& es = r.array(r.member(*e, ep, "relative_rmse"), ep + "/relative_rmse", ds.size());
      if (ds.size() > 4096) r.fail(ep, "more than 4096 entries");
      for (std::size_t i = 0; i < ds.size(); ++i) {
        const double d = r.number(ds[i], ep + "/relative_distance/" + std::to_string(i));
        if (!(d > 0) || (i > 0 && !(d > l.error.relative_distance.back())))
          r.fail(ep + "/relative_distance/" + std::to_string(i), "distances must be positive and increasing");
        const double err = r.number(es[i], ep + "/relative_rmse/" + std::to_string(i));
        if (err < 0) r.fail(ep + "/relative_rmse/" + std::to_string(i), "negative error");
        l.error.relative_distance.push_back(d);
        l.error.relative_rmse.push_back(err);
      }
    }
    m.levels.push_back(std::move(l));
  }

  if (const json* aj = r.optional_member(j, "attachments")) {
    const json& list = r.array(*aj, "/attachments", std::size_t(-1));
    if (list.size() > 64) r.fail("/attachments", "more than 64 attachments");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string at = "/attachments/" + std::to_string(i);
      r.only(list[i], at, {"file", "bytes", "sha256", "media_type"});
      BundleAttachment a;
      BundlePayload p;
      p.file = r.string(r.member(list[i], at, "file"), at + "/file");
      const std::string prefix = "attachments/";
      a.name = p.file.rfind(prefix, 0) == 0 ? p.file.substr(prefix.size()) : std::string();
      if (!is_attachment_name(a.name)) r.fail(at + "/file", "must be attachments/NAME with NAME of [A-Za-z0-9._-]");
      if (!files.insert(p.file).second) r.fail(at + "/file", "\"" + p.file + "\" is listed twice");
      p.bytes = std::uint64_t(r.integer(r.member(list[i], at, "bytes"), at + "/bytes", 0, (long long)limits.max_payload_bytes,
                                        "BundleLimits::max_payload_bytes"));
      p.sha256 = r.string(r.member(list[i], at, "sha256"), at + "/sha256");
      if (p.sha256.size() != 64 || p.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
        r.fail(at + "/sha256", "not 64 lowercase hexadecimal digits");
      a.media_type = r.string(r.member(list[i], at, "media_type"), at + "/media_type");
      m.attachments.emplace_back(std::move(a), std::move(p));
    }
  }
  if (const json* mj = r.optional_member(j, "models")) {
    if (m.format_version < 4) r.fail("/models", "needs format_version 4");
    const json& list = r.array(*mj, "/models", std::size_t(-1));
    if (list.size() > limits.max_models)
      r.fail("/models", "more than BundleLimits::max_models (" + std::to_string(limits.max_models) + ") models");
    std::set<std::string> names;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string at = "/models/" + std::to_string(i);
      r.only(list[i], at, {"name", "type", "section", "payloads"});
      BundleModelInfo model;
      model.name = r.string(r.member(list[i], at, "name"), at + "/name");
      if (!is_attachment_name(model.name)) r.fail(at + "/name", "must be 1-128 of [A-Za-z0-9._-]");
      if (!names.insert(model.name).second) r.fail(at + "/name", "\"" + model.name + "\" is given twice");
      model.type = r.string(r.member(list[i], at, "type"), at + "/type");
      if (model.type.empty() || model.type.size() > 64 ||
          model.type.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-") != std::string::npos)
        r.fail(at + "/type", "must be 1-64 of [a-z0-9-]");
      const json& section = r.member(list[i], at, "section");
      if (!section.is_object()) r.fail(at + "/section", "expected an object");
      model.section = section.dump();
      const json& payloads = r.array(r.member(list[i], at, "payloads"), at + "/payloads", std::size_t(-1));
      if (payloads.size() > limits.max_model_payloads)
        r.fail(at + "/payloads", "more than BundleLimits::max_model_payloads (" + std::to_string(limits.max_model_payloads) + ")");
      std::set<std::string> payload_names;
      for (std::size_t q = 0; q < payloads.size(); ++q) {
        const std::string pp = at + "/payloads/" + std::to_string(q);
        r.only(payloads[q], pp, {"name", "file", "bytes", "sha256"});
        const std::string name = r.string(r.member(payloads[q], pp, "name"), pp + "/name");
        if (!is_attachment_name(name)) r.fail(pp + "/name", "must be 1-128 of [A-Za-z0-9._-]");
        if (!payload_names.insert(name).second) r.fail(pp + "/name", "\"" + name + "\" is given twice");
        BundlePayload p;
        p.file = r.string(r.member(payloads[q], pp, "file"), pp + "/file");
        if (p.file != "models/" + model.name + "/" + name) r.fail(pp + "/file", "must be models/" + model.name + "/" + name);
        if (!files.insert(p.file).second) r.fail(pp + "/file", "\"" + p.file + "\" is listed twice");
        p.bytes = std::uint64_t(r.integer(r.member(payloads[q], pp, "bytes"), pp + "/bytes", 0,
                                          (long long)limits.max_payload_bytes, "BundleLimits::max_payload_bytes"));
        p.sha256 = r.string(r.member(payloads[q], pp, "sha256"), pp + "/sha256");
        if (p.sha256.size() != 64 || p.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
          r.fail(pp + "/sha256", "not 64 lowercase hexadecimal digits");
        model.payloads.emplace_back(name, std::move(p));
      }
      m.models.push_back(std::move(model));
    }
  }
  if (const json* vj = r.optional_member(j, "volume")) {
    r.only(*vj, "/volume", {"file", "bytes", "sha256", "pixel_type", "bounds", "counts", "voxel_size", "sh_bands",
                            "channels", "window", "radiance_unit"});
    BundleVolumeInfo v;
    v.payload = r.payload(*vj, "/volume", limits);
    if (!files.insert(v.payload.file).second) r.fail("/volume/file", "\"" + v.payload.file + "\" is listed twice");
    const json& b = r.member(*vj, "/volume", "bounds");
    r.only(b, "/volume/bounds", {"min", "max"});
    v.lo = r.vec3(r.member(b, "/volume/bounds", "min"), "/volume/bounds/min");
    v.hi = r.vec3(r.member(b, "/volume/bounds", "max"), "/volume/bounds/max");
    const json& counts = r.array(r.member(*vj, "/volume", "counts"), "/volume/counts", 3);
    for (int a = 0; a < 3; ++a) v.counts[a] = int(r.integer(counts[a], "/volume/counts/" + std::to_string(a), 1, 4096));
    if (std::uint64_t(v.counts.x) * v.counts.y * v.counts.z > (1u << 24))
      r.fail("/volume/counts", "more than 2^24 voxels");
    v.voxel_size = r.number(r.member(*vj, "/volume", "voxel_size"), "/volume/voxel_size");
    if (!(v.voxel_size > 0)) r.fail("/volume/voxel_size", "must be positive");
    for (int a = 0; a < 3; ++a)
      if (std::abs((v.hi[a] - v.lo[a]) - v.counts[a] * v.voxel_size) > 1e-6 * std::max(1.0, v.counts[a] * v.voxel_size))
        r.fail("/volume/bounds", "extent does not equal counts × voxel_size");
    v.bands = int(r.integer(r.member(*vj, "/volume", "sh_bands"), "/volume/sh_bands", 1, 8));
    v.channels = int(r.integer(r.member(*vj, "/volume", "channels"), "/volume/channels", 1, 3));
    if (v.channels == 2) r.fail("/volume/channels", "must be 1 or 3");
    const std::string window = r.string(r.member(*vj, "/volume", "window"), "/volume/window");
    bool known = false;
    for (sh::Window w : {sh::Window::none, sh::Window::lanczos, sh::Window::hann, sh::Window::vallee_poussin})
      if (window == window_name(w)) v.window = w, known = true;
    if (!known) r.fail("/volume/window", "unknown window \"" + window + "\"");
    const std::string unit = m.quantity == PhotometricQuantity::photometric ? "cd/m^2" : "W/(m^2 sr)";
    if (r.string(r.member(*vj, "/volume", "radiance_unit"), "/volume/radiance_unit") != unit)
      r.fail("/volume/radiance_unit", "must be \"" + unit + "\" for intensity in " + intensity);
    const std::uint64_t decoded = std::uint64_t(v.counts.x) * v.counts.y * v.counts.z * v.bands * v.bands * v.channels * 4;
    if (decoded > limits.max_decoded_bytes) r.fail("/volume", "would decode to " + std::to_string(decoded) + " bytes, above BundleLimits::max_decoded_bytes (" +
                                                               std::to_string(limits.max_decoded_bytes) + ")");
    m.volume = v;
  }
  return m;
}

}  // namespace detail
LUMX_NAMESPACE_END
