/// @file   MaskDilation.cc
/// @brief  dilateMaxNorm: separable max-norm dilation on the 64-bit words of mask leaves.
#include <ghostfx/vdbio/MaskDilation.h>

#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

namespace {

using MaskLeaf = openvdb::MaskTree::LeafNodeType;
using Word = std::uint64_t;
constexpr int DIM = int(MaskLeaf::DIM); // 8: words per leaf, bytes per word, bits per byte
static_assert(DIM == 8 && MaskLeaf::SIZE == 512, "the word layout below assumes 8^3 leaves");

/// The eight words of a leaf's mask (zeros for a missing leaf).
void loadWords(const MaskLeaf* leaf, Word* words)
{
    for (int n = 0; n < DIM; ++n) words[n] = leaf ? leaf->getValueMask().getWord<Word>(n) : 0;
}

/// Byte `b` repeated in all eight bytes of a word.
constexpr Word everyByte(unsigned b) { return 0x0101010101010101ull * (b & 0xFFu); }

/// Word x of the dilation along x: the OR of words x - k .. x + k of the row lo | c | hi.
Word dilateX(const Word* lo, const Word* c, const Word* hi, int x, int k)
{
    Word r = 0;
    for (int t = x - k; t <= x + k; ++t) r |= t < 0 ? lo[t + DIM] : t >= DIM ? hi[t - DIM] : c[t];
    return r;
}

/// Dilation along y of one word: byte y gets the OR of bytes y - k .. y + k, those beyond the
/// word taken from the same word of the neighbouring leaves (lo: y - 1, hi: y + 1).
Word dilateY(Word lo, Word c, Word hi, int k)
{
    Word r = c;
    for (int s = 1; s <= k; ++s) {
        if (s < DIM) r |= (c << (8 * s)) | (c >> (8 * s));
        const int rest = 8 * (DIM - s); // bits from the neighbour: the s bytes next to c
        r |= (s == DIM ? lo : lo >> rest) | (s == DIM ? hi : hi << rest);
    }
    return r;
}

/// Dilation along z of one word: bit z of each byte gets the OR of bits z - k .. z + k of
/// its byte, those beyond the byte taken from the same byte of the neighbouring leaves.
Word dilateZ(Word lo, Word c, Word hi, int k)
{
    Word r = c;
    for (int s = 1; s <= k; ++s) {
        if (s < DIM) {
            r |= (c << s) & everyByte(0xFFu << s);
            r |= (c >> s) & everyByte(0xFFu >> s);
        }
        const int rest = DIM - s;
        r |= (lo >> rest) & everyByte(0xFFu >> rest);
        r |= (hi << rest) & everyByte(0xFFu << rest);
    }
    return r;
}

/// Adds to `tree` (empty) leaves beside every leaf of `input`, at +-steps[0..count): the
/// leaves a pass's bits may reach (the pass prunes those left empty).
void touchNeighbours(openvdb::MaskTree& tree, const openvdb::MaskTree& input,
                     const openvdb::Coord* steps, int count)
{
    std::vector<openvdb::Coord> origins;
    origins.reserve(input.leafCount());
    for (auto it = input.cbeginLeaf(); it; ++it) origins.push_back(it->origin());
    openvdb::tree::ValueAccessor<openvdb::MaskTree> acc(tree);
    for (const openvdb::Coord& o : origins) {
        for (int s = 0; s < count; ++s) {
            acc.touchLeaf(o - steps[s]);
            acc.touchLeaf(o + steps[s]);
        }
    }
}

/// One separable pass: every voxel within k (<= DIM) of an active voxel along `axis`.
void dilateAlong(openvdb::MaskTree& tree, int axis, int k)
{
    const openvdb::MaskTree input(tree); // the old bits; `tree` receives the new ones
    openvdb::Coord step(0);
    step[axis] = DIM;
    touchNeighbours(tree, input, &step, 1);
    openvdb::tree::LeafManager<openvdb::MaskTree> leaves(tree);
    leaves.foreach ([&](MaskLeaf& leaf, std::size_t) {
        openvdb::tree::ValueAccessor<const openvdb::MaskTree> acc(input);
        const openvdb::Coord o = leaf.origin();
        Word lo[DIM], c[DIM], hi[DIM];
        loadWords(acc.probeConstLeaf(o - step), lo);
        loadWords(acc.probeConstLeaf(o), c);
        loadWords(acc.probeConstLeaf(o + step), hi);
        openvdb::util::NodeMask<3>& out = leaf.getValueMask();
        for (int n = 0; n < DIM; ++n) {
            Word w = 0;
            switch (axis) {
            case 0:
                w = dilateX(lo, c, hi, n, k);
                break;
            case 1:
                w = dilateY(lo[n], c[n], hi[n], k);
                break;
            default:
                w = dilateZ(lo[n], c[n], hi[n], k);
                break;
            }
            out.getWord<Word>(n) = w;
        }
    });
    openvdb::tools::pruneInactive(tree);
}

/// One pass adding the face neighbours: the union of dilateX, dilateY and dilateZ by one
/// voxel, each from the input.
void dilateFacesOnce(openvdb::MaskTree& tree)
{
    const openvdb::MaskTree input(tree);
    const openvdb::Coord steps[3] = {openvdb::Coord(DIM, 0, 0), openvdb::Coord(0, DIM, 0),
                                     openvdb::Coord(0, 0, DIM)};
    touchNeighbours(tree, input, steps, 3);
    openvdb::tree::LeafManager<openvdb::MaskTree> leaves(tree);
    leaves.foreach ([&](MaskLeaf& leaf, std::size_t) {
        openvdb::tree::ValueAccessor<const openvdb::MaskTree> acc(input);
        const openvdb::Coord o = leaf.origin();
        Word c[DIM], lo[3][DIM], hi[3][DIM];
        loadWords(acc.probeConstLeaf(o), c);
        for (int axis = 0; axis < 3; ++axis) {
            loadWords(acc.probeConstLeaf(o - steps[axis]), lo[axis]);
            loadWords(acc.probeConstLeaf(o + steps[axis]), hi[axis]);
        }
        openvdb::util::NodeMask<3>& out = leaf.getValueMask();
        for (int n = 0; n < DIM; ++n) {
            out.getWord<Word>(n) = dilateX(lo[0], c, hi[0], n, 1)
                                   | dilateY(lo[1][n], c[n], hi[1][n], 1)
                                   | dilateZ(lo[2][n], c[n], hi[2][n], 1);
        }
    });
    openvdb::tools::pruneInactive(tree);
}

} // namespace

void dilateFaces(openvdb::MaskTree& mask)
{
    if (mask.empty()) return;
    if (mask.hasActiveTiles()) mask.voxelizeActiveTiles();
    dilateFacesOnce(mask);
}

void dilateMaxNorm(openvdb::MaskTree& mask, int k)
{
    if (k < 0) {
        OPENVDB_THROW(openvdb::ValueError,
                      "dilateMaxNorm: k = " + std::to_string(k) + ", expected k >= 0");
    }
    if (k == 0 || mask.empty()) return;
    if (mask.hasActiveTiles()) mask.voxelizeActiveTiles();
    // Max-norm dilations add: k = 8 + 8 + ... + rest, each within one neighbouring leaf.
    for (int left = k; left > 0; left -= DIM) {
        const int part = std::min(left, DIM);
        for (int axis = 0; axis < 3; ++axis) dilateAlong(mask, axis, part);
    }
}

} // namespace vdbio
} // namespace ghostfx
