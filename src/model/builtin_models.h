// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/model/builtin_models.h — the representations the core library registers (one line each in
// registry.cpp).
#pragma once

#include <lumx/model/registry.h>

LUMX_NAMESPACE_BEGIN
namespace detail {

ModelType apl_model_type();        // apl_model.cpp
ModelType far_field_model_type();  // src/io/bundle/far_field_codec.cpp (the IES payload is a file format)

}  // namespace detail
LUMX_NAMESPACE_END
