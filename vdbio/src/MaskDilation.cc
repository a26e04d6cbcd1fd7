/// @file   MaskDilation.cc
/// @brief  dilateMaxNorm: separable max-norm dilation on the 64-bit words of mask leaves.
#include <ghostfx/vdbio/MaskDilation.h>

#include <openvdb/tree/ValueAccessor.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

namespace {

using MaskLeaf = openvdb::MaskTree::LeafNodeType;
using Word = std::uint64_t;
constexpr int DIM = int(MaskLeaf::DIM); // 8: words per leaf, bytes per word, bits per byte
static_assert(DIM == 8 && MaskLeaf::SIZE == 512, "the word layout below assumes 8^3 leaves");

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

/// One dilation pass over `tree`, in place: `words(acc, origin, out)` gives the eight new mask
/// words of the leaf at `origin` from the current masks (read through `acc`; a missing leaf
/// reads as empty), reaching at most one leaf along each of steps[0..count) either way. The
/// new words of every leaf, and of every missing leaf beside one, are all computed before any
/// is written, so the pass reads its input as it was without copying the tree. Leaves added
/// take the value of the tile they replace (for a level set: +-background), with only the
/// dilated voxels active, as Tree::topologyUnion adds them.
template <typename TreeT, typename WordsFn>
void dilateInPlace(TreeT& tree, const openvdb::Coord* steps, int count, const WordsFn& words)
{
    using Leaf = typename TreeT::LeafNodeType;
    using ConstAccessor = openvdb::tree::ValueAccessor<const TreeT>;
    std::vector<Leaf*> leaves;
    leaves.reserve(tree.leafCount());
    tree.getNodes(leaves);
    const std::size_t n = leaves.size();
    std::vector<Word> grown(n * DIM);
    // Existing leaves' new words, and the missing leaves beside them (per thread, merged).
    tbb::enumerable_thread_specific<std::vector<openvdb::Coord>> missingPerThread;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64),
                      [&](const tbb::blocked_range<std::size_t>& range) {
        ConstAccessor acc(tree);
        std::vector<openvdb::Coord>& missing = missingPerThread.local();
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const openvdb::Coord o = leaves[i]->origin();
            words(acc, o, &grown[i * DIM]);
            for (int s = 0; s < count; ++s) {
                for (const openvdb::Coord& q : {o - steps[s], o + steps[s]}) {
                    if (!acc.probeConstLeaf(q)) missing.push_back(q);
                }
            }
        }
    });
    std::vector<openvdb::Coord> missing;
    for (const std::vector<openvdb::Coord>& part : missingPerThread) // sorted below
        missing.insert(missing.end(), part.begin(), part.end());
    std::sort(missing.begin(), missing.end());
    missing.erase(std::unique(missing.begin(), missing.end()), missing.end());
    std::vector<Word> added(missing.size() * DIM);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, missing.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& range) {
        ConstAccessor acc(tree);
        for (std::size_t i = range.begin(); i != range.end(); ++i)
            words(acc, missing[i], &added[i * DIM]);
    });
    // Only now the writes: existing leaves' masks in parallel, then the new leaves.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64),
                      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            auto& mask = leaves[i]->getValueMask();
            for (int w = 0; w < DIM; ++w) mask.template getWord<Word>(w) = grown[i * DIM + w];
        }
    });
    openvdb::tree::ValueAccessor<TreeT> acc(tree);
    for (std::size_t i = 0; i < missing.size(); ++i) {
        const Word* w = &added[i * DIM];
        if (std::all_of(w, w + DIM, [](Word x) { return x == 0; })) continue;
        auto leaf = std::make_unique<Leaf>(missing[i], acc.getValue(missing[i]), false);
        for (int k = 0; k < DIM; ++k) leaf->getValueMask().template getWord<Word>(k) = w[k];
        acc.addLeaf(leaf.release());
    }
}

/// The eight words of the leaf at `o` in `acc`'s tree (zeros for a missing leaf).
template <typename AccessorT>
void loadWordsAt(const AccessorT& acc, const openvdb::Coord& o, Word* words)
{
    const auto* leaf = acc.probeConstLeaf(o);
    for (int n = 0; n < DIM; ++n)
        words[n] = leaf ? leaf->getValueMask().template getWord<Word>(n) : 0;
}

/// One separable pass: every voxel within k (<= DIM) of an active voxel along `axis`.
void dilateAlong(openvdb::MaskTree& tree, int axis, int k)
{
    openvdb::Coord step(0);
    step[axis] = DIM;
    dilateInPlace(tree, &step, 1, [&](const auto& acc, const openvdb::Coord& o, Word* out) {
        Word lo[DIM], c[DIM], hi[DIM];
        loadWordsAt(acc, o - step, lo);
        loadWordsAt(acc, o, c);
        loadWordsAt(acc, o + step, hi);
        for (int n = 0; n < DIM; ++n) {
            switch (axis) {
            case 0:
                out[n] = dilateX(lo, c, hi, n, k);
                break;
            case 1:
                out[n] = dilateY(lo[n], c[n], hi[n], k);
                break;
            default:
                out[n] = dilateZ(lo[n], c[n], hi[n], k);
                break;
            }
        }
    });
}

/// One pass adding the face neighbours: the union of dilateX, dilateY and dilateZ by one
/// voxel, each from the input.
template <typename TreeT>
void dilateFacesOnce(TreeT& tree)
{
    const openvdb::Coord steps[3] = {openvdb::Coord(DIM, 0, 0), openvdb::Coord(0, DIM, 0),
                                     openvdb::Coord(0, 0, DIM)};
    dilateInPlace(tree, steps, 3, [&](const auto& acc, const openvdb::Coord& o, Word* out) {
        Word c[DIM], lo[3][DIM], hi[3][DIM];
        loadWordsAt(acc, o, c);
        for (int axis = 0; axis < 3; ++axis) {
            loadWordsAt(acc, o - steps[axis], lo[axis]);
            loadWordsAt(acc, o + steps[axis], hi[axis]);
        }
        for (int n = 0; n < DIM; ++n) {
            out[n] = dilateX(lo[0], c, hi[0], n, 1) | dilateY(lo[1][n], c[n], hi[1][n], 1)
                     | dilateZ(lo[2][n], c[n], hi[2][n], 1);
        }
    });
}

} // namespace

void dilateFaces(openvdb::MaskTree& mask)
{
    if (mask.empty()) return;
    if (mask.hasActiveTiles()) mask.voxelizeActiveTiles();
    dilateFacesOnce(mask);
}

void dilateFaces(openvdb::FloatTree& tree)
{
    if (tree.empty()) return;
    if (tree.hasActiveTiles()) tree.voxelizeActiveTiles();
    dilateFacesOnce(tree);
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
