// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/io/bundle/bundle_manifest.h — the bundle manifest ⇄ JSON (nlohmann-json).
//
// The JSON layout is specified by schema/bundle-manifest.schema.json; the parser here enforces the same
// rules (and the cross-field ones a schema cannot state: array lengths equal apl_count, parents in range,
// payload names inside the bundle), reporting the JSON pointer of the offending field.
#pragma once

#include <lumx/io/bundle_io.h>

#include <string>
#include <string_view>

LUMX_NAMESPACE_BEGIN
namespace detail {

std::string manifest_to_json(const BundleManifest& m);
BundleManifest parse_manifest(std::string_view text, const std::string& file, const BundleLimits& limits);
/// Whether `text` is one JSON object within the manifest's nesting limit (a codec's section).
bool is_json_object_text(const std::string& text);
/// Attachment names: 1–128 of [A-Za-z0-9._-], not "." or "..".
bool is_attachment_name(const std::string& name);
/// Channel names as stored in map payloads: {"Y"} or {"R","G","B"}.
std::vector<std::string> map_channel_names(ChannelLayout layout);
/// Channel names of the volume payload: "sh00.R" ... one per (channel, coefficient), in memory order.
std::vector<std::string> volume_channel_names(int channels, int bands);

}  // namespace detail
LUMX_NAMESPACE_END
