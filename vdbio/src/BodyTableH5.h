/// @file   BodyTableH5.h
/// @brief  The `/bodies` group of a statistics file (layout in BodyTable.h), for Stats.cc.
#pragma once

#include <ghostfx/vdbio/BodyTable.h>

#include <H5Cpp.h>

namespace ghostfx {
namespace vdbio {

/// Write `rows` as the group `/bodies` of `file` (nothing without rows).
void writeBodiesGroup(H5::H5File& file, const std::vector<BodyRow>& rows);

} // namespace vdbio
} // namespace ghostfx
