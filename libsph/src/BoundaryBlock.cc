/// @file   BoundaryBlock.cc
/// @brief  Deterministic ordering and the grid of a boundary block.
#include "ghostfx/sph/BoundaryBlock.h"

#include <algorithm>
#include <numeric>

namespace ghostfx {
namespace sph {

void BoundaryBlock::rebuild()
{
    const auto& ids = mParticles.ids();
    if (!std::is_sorted(ids.begin(), ids.end())) {
        std::vector<Index> byId(ids.size());
        std::iota(byId.begin(), byId.end(), Index(0));
        std::sort(byId.begin(), byId.end(), [&ids](Index a, Index b) { return ids[a] < ids[b]; });
        mParticles.reorder(byId);
    }
    mGrid.sortParticles(mParticles);
    mStale = false;
}

} // namespace sph
} // namespace ghostfx
