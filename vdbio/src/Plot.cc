/// @file   Plot.cc
/// @brief  Error-versus-cost scatter plots (Plot.h): layout, ticks, a 5x7 bitmap font and a
///         small RGB canvas with anti-aliased discs, rings and segments, written as PNG.
/// @details The canvas holds 8-bit sRGB colours, so blending and the palette work in the space
///          the colours were chosen in; the image is converted to linear floats only for
///          writePng(), with the exact inverse of its transfer curve, so every solid pixel reads
///          back as the palette colour it was drawn with.
#include <ghostfx/vdbio/Plot.h>

#include "PngFile.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace ghostfx {
namespace vdbio {

namespace {

using Rgb = std::array<std::uint8_t, 3>;

// Colours (sRGB). The series palette is Tableau 10 without its pink and grey: eight hues that
// stay apart for the common forms of colour blindness and print well.
constexpr Rgb WHITE{255, 255, 255};
constexpr Rgb TEXT{30, 30, 30};
constexpr Rgb AXES{70, 70, 70};
constexpr Rgb GRID{230, 230, 230};
constexpr Rgb FRONT{25, 25, 25};
constexpr Rgb LEGEND_EDGE{180, 180, 180};
constexpr Rgb PALETTE[] = {{78, 121, 167}, {242, 142, 43}, {225, 87, 89},   {118, 183, 178},
                           {89, 161, 79},  {237, 201, 72}, {176, 122, 161}, {156, 117, 95}};
constexpr std::size_t PALETTE_SIZE = sizeof(PALETTE) / sizeof(PALETTE[0]);
// Marker outlines are the fill colour darkened to this fraction, so light hues (yellow) still
// stand out on white and overlapping markers stay apart.
constexpr double OUTLINE_SHADE = 0.6;

// Font: 5 columns by 9 rows per glyph (rows 0-6 are the 5x7 cap height, rows 7-8 descenders),
// one byte per row with bit 4 the leftmost column, for printable ASCII 32..126. Glyphs advance
// by 6 columns; lines take 9 rows plus spacing.
constexpr int GLYPH_ROWS = 9, GLYPH_COLUMNS = 5, CAP_ROWS = 7, ADVANCE = 6;
constexpr unsigned char FIRST_GLYPH = 32, LAST_GLYPH = 126;
constexpr std::uint8_t FONT[LAST_GLYPH - FIRST_GLYPH + 1][GLYPH_ROWS] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // space
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04, 0x00, 0x00}, // !
    {0x0a, 0x0a, 0x0a, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // "
    {0x0a, 0x0a, 0x1f, 0x0a, 0x1f, 0x0a, 0x0a, 0x00, 0x00}, // #
    {0x04, 0x0f, 0x14, 0x0e, 0x05, 0x1e, 0x04, 0x00, 0x00}, // $
    {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03, 0x00, 0x00}, // %
    {0x0c, 0x12, 0x14, 0x08, 0x15, 0x12, 0x0d, 0x00, 0x00}, // &
    {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // '
    {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02, 0x00, 0x00}, // (
    {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08, 0x00, 0x00}, // )
    {0x00, 0x04, 0x15, 0x0e, 0x15, 0x04, 0x00, 0x00, 0x00}, // *
    {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00, 0x00, 0x00}, // +
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c, 0x04, 0x08}, // ,
    {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00, 0x00, 0x00}, // -
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c, 0x00, 0x00}, // .
    {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00, 0x00, 0x00}, // /
    {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e, 0x00, 0x00}, // 0
    {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e, 0x00, 0x00}, // 1
    {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f, 0x00, 0x00}, // 2
    {0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e, 0x00, 0x00}, // 3
    {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02, 0x00, 0x00}, // 4
    {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e, 0x00, 0x00}, // 5
    {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e, 0x00, 0x00}, // 6
    {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08, 0x00, 0x00}, // 7
    {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e, 0x00, 0x00}, // 8
    {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c, 0x00, 0x00}, // 9
    {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00, 0x00, 0x00}, // :
    {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x04, 0x08, 0x00}, // ;
    {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02, 0x00, 0x00}, // <
    {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00, 0x00, 0x00}, // =
    {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08, 0x00, 0x00}, // >
    {0x0e, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04, 0x00, 0x00}, // ?
    {0x0e, 0x11, 0x01, 0x0d, 0x15, 0x15, 0x0e, 0x00, 0x00}, // @
    {0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11, 0x00, 0x00}, // A
    {0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e, 0x00, 0x00}, // B
    {0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e, 0x00, 0x00}, // C
    {0x1c, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1c, 0x00, 0x00}, // D
    {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f, 0x00, 0x00}, // E
    {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x10, 0x00, 0x00}, // F
    {0x0e, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0f, 0x00, 0x00}, // G
    {0x11, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11, 0x00, 0x00}, // H
    {0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e, 0x00, 0x00}, // I
    {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c, 0x00, 0x00}, // J
    {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11, 0x00, 0x00}, // K
    {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1f, 0x00, 0x00}, // L
    {0x11, 0x1b, 0x15, 0x15, 0x11, 0x11, 0x11, 0x00, 0x00}, // M
    {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11, 0x00, 0x00}, // N
    {0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e, 0x00, 0x00}, // O
    {0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10, 0x10, 0x00, 0x00}, // P
    {0x0e, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0d, 0x00, 0x00}, // Q
    {0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11, 0x00, 0x00}, // R
    {0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e, 0x00, 0x00}, // S
    {0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x00}, // T
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e, 0x00, 0x00}, // U
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x0a, 0x04, 0x00, 0x00}, // V
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a, 0x00, 0x00}, // W
    {0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11, 0x00, 0x00}, // X
    {0x11, 0x11, 0x11, 0x0a, 0x04, 0x04, 0x04, 0x00, 0x00}, // Y
    {0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f, 0x00, 0x00}, // Z
    {0x0e, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0e, 0x00, 0x00}, // [
    {0x00, 0x10, 0x08, 0x04, 0x02, 0x01, 0x00, 0x00, 0x00}, // backslash
    {0x0e, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0e, 0x00, 0x00}, // ]
    {0x04, 0x0a, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // ^
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f, 0x00}, // _
    {0x08, 0x04, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, // `
    {0x00, 0x00, 0x0e, 0x01, 0x0f, 0x11, 0x0f, 0x00, 0x00}, // a
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1e, 0x00, 0x00}, // b
    {0x00, 0x00, 0x0e, 0x10, 0x10, 0x11, 0x0e, 0x00, 0x00}, // c
    {0x01, 0x01, 0x0d, 0x13, 0x11, 0x11, 0x0f, 0x00, 0x00}, // d
    {0x00, 0x00, 0x0e, 0x11, 0x1f, 0x10, 0x0e, 0x00, 0x00}, // e
    {0x06, 0x09, 0x08, 0x1c, 0x08, 0x08, 0x08, 0x00, 0x00}, // f
    {0x00, 0x00, 0x0f, 0x11, 0x11, 0x11, 0x0f, 0x01, 0x0e}, // g
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11, 0x00, 0x00}, // h
    {0x04, 0x00, 0x0c, 0x04, 0x04, 0x04, 0x0e, 0x00, 0x00}, // i
    {0x02, 0x00, 0x06, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c}, // j
    {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12, 0x00, 0x00}, // k
    {0x0c, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e, 0x00, 0x00}, // l
    {0x00, 0x00, 0x1a, 0x15, 0x15, 0x11, 0x11, 0x00, 0x00}, // m
    {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11, 0x00, 0x00}, // n
    {0x00, 0x00, 0x0e, 0x11, 0x11, 0x11, 0x0e, 0x00, 0x00}, // o
    {0x00, 0x00, 0x1e, 0x11, 0x11, 0x11, 0x1e, 0x10, 0x10}, // p
    {0x00, 0x00, 0x0f, 0x11, 0x11, 0x11, 0x0f, 0x01, 0x01}, // q
    {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10, 0x00, 0x00}, // r
    {0x00, 0x00, 0x0f, 0x10, 0x0e, 0x01, 0x1e, 0x00, 0x00}, // s
    {0x08, 0x08, 0x1c, 0x08, 0x08, 0x09, 0x06, 0x00, 0x00}, // t
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0d, 0x00, 0x00}, // u
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x0a, 0x04, 0x00, 0x00}, // v
    {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0a, 0x00, 0x00}, // w
    {0x00, 0x00, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x00, 0x00}, // x
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x11, 0x0f, 0x01, 0x0e}, // y
    {0x00, 0x00, 0x1f, 0x02, 0x04, 0x08, 0x1f, 0x00, 0x00}, // z
    {0x02, 0x04, 0x04, 0x08, 0x04, 0x04, 0x02, 0x00, 0x00}, // {
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x00}, // |
    {0x08, 0x04, 0x04, 0x02, 0x04, 0x04, 0x08, 0x00, 0x00}, // }
    {0x00, 0x00, 0x08, 0x15, 0x02, 0x00, 0x00, 0x00, 0x00}, // ~
};

// Longest series name shown in the legend (characters); longer names end in "..".
constexpr std::size_t LEGEND_NAME_CHARS = 22;
// Smallest distance (pixels, at text scale 1) between neighbouring ticks on a linear axis, and
// the gap kept between neighbouring tick labels.
constexpr int MIN_TICK_SPACING = 40, TICK_LABEL_GAP = 4;
// Steps giving more ticks than this are not tried (and the loops stay short for any range).
constexpr double MAX_TICKS = 200;
// Unlabelled ticks at 2 and 5 are drawn only where a decade is at least this long (pixels, at
// text scale 1): the gap between 1 and 2 is then about 8 pixels.
constexpr double MIN_DECADE_FOR_SUBTICKS = 28.0;
// Share of each axis kept free on both ends of the data (at least a marker and a bit).
constexpr double AXIS_MARGIN_FRACTION = 0.05;
// A single value (zero data range) gets this much room either side: half a decade on a log
// axis, a tenth of the value (or 1 for 0) on a linear one.
constexpr double SINGLE_VALUE_HALF_DECADES = 0.5, SINGLE_VALUE_FRACTION = 0.1;

/// The 8-bit sRGB value as linear light: the exact inverse of writePng's encoding, so a solid
/// pixel reads back as the same byte.
float linearOf(std::uint8_t srgb)
{
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) {
            const double c = i / 255.0;
            t[std::size_t(i)] =
                float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
        }
        return t;
    }();
    return table[srgb];
}

Rgb shade(const Rgb& c, double factor)
{
    return {std::uint8_t(std::lround(c[0] * factor)), std::uint8_t(std::lround(c[1] * factor)),
            std::uint8_t(std::lround(c[2] * factor))};
}

/// Width in pixels of `text` drawn at `scale` (no trailing gap).
int textWidth(const std::string& text, int scale)
{
    return text.empty() ? 0 : (int(text.size()) * ADVANCE - 1) * scale;
}

/// An axis-aligned pixel rectangle, inclusive bounds.
struct Box
{
    int left = 0, top = 0, right = -1, bottom = -1;
    bool overlaps(const Box& o) const
    {
        return left <= o.right && o.left <= right && top <= o.bottom && o.top <= bottom;
    }
    bool inside(const Box& o) const
    {
        return left >= o.left && right <= o.right && top >= o.top && bottom <= o.bottom;
    }
};

/// An RGB image with the few shapes a plot needs. Coordinates are pixels, x to the right and y
/// down; a pixel's centre is at integer coordinates. Anything outside the image is clipped.
class Canvas
{
public:
    Canvas(int width, int height)
        : mWidth(width)
        , mHeight(height)
        , mPixels(std::size_t(width) * std::size_t(height), WHITE)
    {}

    /// Blend `c` over the pixel with coverage `alpha` in [0, 1] (1 sets it exactly).
    void blend(int x, int y, const Rgb& c, double alpha)
    {
        if (x < 0 || y < 0 || x >= mWidth || y >= mHeight || alpha <= 0.0) return;
        Rgb& p = mPixels[std::size_t(y) * std::size_t(mWidth) + std::size_t(x)];
        if (alpha >= 1.0) {
            p = c;
            return;
        }
        for (int i = 0; i < 3; ++i) p[i] = std::uint8_t(std::lround(p[i] + (c[i] - p[i]) * alpha));
    }

    void fillRect(int x0, int y0, int x1, int y1, const Rgb& c)
    {
        for (int y = std::max(y0, 0); y <= std::min(y1, mHeight - 1); ++y) {
            for (int x = std::max(x0, 0); x <= std::min(x1, mWidth - 1); ++x) blend(x, y, c, 1.0);
        }
    }

    /// One-pixel outline of a rectangle.
    void frameRect(const Box& b, const Rgb& c)
    {
        fillRect(b.left, b.top, b.right, b.top, c);
        fillRect(b.left, b.bottom, b.right, b.bottom, c);
        fillRect(b.left, b.top, b.left, b.bottom, c);
        fillRect(b.right, b.top, b.right, b.bottom, c);
    }

    /// Filled disc of `radius` (pixels) centred on a pixel, with a half-pixel soft edge.
    void disc(int cx, int cy, double radius, const Rgb& c) { ring(cx, cy, -1.0, radius, c); }

    /// Annulus between `inner` and `outer` radius (pixels), soft edges; inner < 0 fills it.
    void ring(int cx, int cy, double inner, double outer, const Rgb& c)
    {
        const int reach = int(std::ceil(outer + 1.0));
        for (int dy = -reach; dy <= reach; ++dy) {
            for (int dx = -reach; dx <= reach; ++dx) {
                const double d = std::sqrt(double(dx * dx + dy * dy));
                double cover = std::clamp(outer + 0.5 - d, 0.0, 1.0);
                if (inner >= 0.0) cover = std::min(cover, std::clamp(d - inner + 0.5, 0.0, 1.0));
                blend(cx + dx, cy + dy, c, cover);
            }
        }
    }

    /// Straight segment of `width` pixels between two points, round caps, soft edges. Coverage
    /// is the distance from each pixel centre to the segment, so any slope looks the same.
    void segment(double x0, double y0, double x1, double y1, double width, const Rgb& c)
    {
        const double half = 0.5 * width;
        const int xa = int(std::floor(std::min(x0, x1) - half - 1)),
                  xb = int(std::ceil(std::max(x0, x1) + half + 1));
        const int ya = int(std::floor(std::min(y0, y1) - half - 1)),
                  yb = int(std::ceil(std::max(y0, y1) + half + 1));
        const double dx = x1 - x0, dy = y1 - y0, length2 = dx * dx + dy * dy;
        for (int y = std::max(ya, 0); y <= std::min(yb, mHeight - 1); ++y) {
            for (int x = std::max(xa, 0); x <= std::min(xb, mWidth - 1); ++x) {
                double t = length2 > 0.0 ? ((x - x0) * dx + (y - y0) * dy) / length2 : 0.0;
                t = std::clamp(t, 0.0, 1.0);
                const double d = std::hypot(x - (x0 + t * dx), y - (y0 + t * dy));
                blend(x, y, c, std::clamp(half + 0.5 - d, 0.0, 1.0));
            }
        }
    }

    /// Draw `text` with its top-left corner at (x, y), each font pixel a `scale` square. When
    /// `upwards`, the text is turned a quarter turn counter-clockwise and reads from bottom to
    /// top, (x, y) then being its bottom-left corner. Characters outside ASCII 32..126 draw '?'.
    void text(int x, int y, const std::string& text, int scale, const Rgb& c, bool upwards = false)
    {
        for (std::size_t i = 0; i < text.size(); ++i) {
            unsigned char ch = static_cast<unsigned char>(text[i]);
            if (ch < FIRST_GLYPH || ch > LAST_GLYPH) ch = '?';
            const std::uint8_t* glyph = FONT[ch - FIRST_GLYPH];
            for (int row = 0; row < GLYPH_ROWS; ++row) {
                for (int column = 0; column < GLYPH_COLUMNS; ++column) {
                    if (!(glyph[row] & (0x10 >> column))) continue;
                    // Position of the font pixel along and across the line of text.
                    const int along = (int(i) * ADVANCE + column) * scale, across = row * scale;
                    for (int sy = 0; sy < scale; ++sy) {
                        for (int sx = 0; sx < scale; ++sx) {
                            if (upwards) {
                                blend(x + across + sy, y - along - sx, c, 1.0);
                            } else {
                                blend(x + along + sx, y + across + sy, c, 1.0);
                            }
                        }
                    }
                }
            }
        }
    }

    /// The image as writePng wants it: linear RGBA floats, opaque, from the top row.
    std::vector<float> linearRgba() const
    {
        std::vector<float> rgba;
        rgba.reserve(mPixels.size() * 4);
        for (const Rgb& p : mPixels) {
            rgba.insert(rgba.end(), {linearOf(p[0]), linearOf(p[1]), linearOf(p[2]), 1.0f});
        }
        return rgba;
    }

private:
    int mWidth, mHeight;
    std::vector<Rgb> mPixels;
};

/// One tick of an axis: its data value, whether it is a major tick (grid line, longer mark) and
/// its label ("" for none).
struct Tick
{
    double value = 0;
    bool major = true;
    std::string label;
};

/// Drop a trailing ".0..." and turn "e-05" / "e+06" into "e-5" / "e6".
std::string compactNumber(std::string s)
{
    const std::size_t e = s.find('e');
    std::string mantissa = s.substr(0, e), exponent = e == std::string::npos ? "" : s.substr(e + 1);
    if (mantissa.find('.') != std::string::npos) {
        while (!mantissa.empty() && mantissa.back() == '0') mantissa.pop_back();
        if (!mantissa.empty() && mantissa.back() == '.') mantissa.pop_back();
    }
    if (exponent.empty()) return mantissa;
    const bool negative = exponent[0] == '-';
    std::size_t digits = (exponent[0] == '-' || exponent[0] == '+') ? 1 : 0;
    while (digits + 1 < exponent.size() && exponent[digits] == '0') ++digits;
    return mantissa + "e" + (negative ? "-" : "") + exponent.substr(digits);
}

/// `mantissa` x 10^`exponent` for a log axis: plain decimals from 0.01 to 9000 ("0.05", "200"),
/// "1e-3" / "2e4" beyond.
std::string logLabel(int mantissa, int exponent)
{
    char buffer[64];
    if (exponent >= -2 && exponent <= 3) {
        std::snprintf(buffer, sizeof(buffer), "%.*f", std::max(0, -exponent),
                      mantissa * std::pow(10.0, exponent));
    } else {
        std::snprintf(buffer, sizeof(buffer), "%de%d", mantissa, exponent);
    }
    return buffer;
}

/// `value` on a linear axis with ticks every `step` (= 1, 2 or 5 x 10^k): as many decimals as
/// the step needs, or an exponent for very large or very small steps.
std::string linearLabel(double value, double step)
{
    if (std::abs(value) < 1e-9 * step) return "0";
    const int stepExponent = int(std::floor(std::log10(step) + 1e-9));
    char buffer[64];
    if (stepExponent >= -4 && std::abs(value) < 1e6) {
        std::snprintf(buffer, sizeof(buffer), "%.*f", std::max(0, -stepExponent), value);
        return buffer;
    }
    const int valueExponent = int(std::floor(std::log10(std::abs(value))));
    std::snprintf(buffer, sizeof(buffer), "%.*e", std::max(0, valueExponent - stepExponent), value);
    return compactNumber(buffer);
}

/// An axis after layout: the shown range in axis units (log10 of the value on a log axis) and
/// the pixels the ends of that range map to.
struct Axis
{
    bool log = true;
    double lo = 0, hi = 1;
    double pixelLo = 0, pixelHi = 1;
    std::vector<Tick> ticks;

    double toAxis(double value) const { return log ? std::log10(value) : value; }
    double pixelOf(double value) const
    {
        return pixelLo + (toAxis(value) - lo) / (hi - lo) * (pixelHi - pixelLo);
    }
    double length() const { return std::abs(pixelHi - pixelLo); }
};

/// Pad the data range [lo, hi] (axis units) so the data keeps `clearance` pixels from both ends
/// of an axis `length` pixels long.
void padRange(Axis& axis, double lo, double hi, double length, double clearance)
{
    if (!(hi > lo)) {
        const double half = axis.log ? SINGLE_VALUE_HALF_DECADES
                                     : (lo != 0.0 ? SINGLE_VALUE_FRACTION * std::abs(lo) : 1.0);
        lo -= half;
        hi += half;
    }
    clearance = std::min(clearance, 0.25 * length);
    const double pad = clearance * (hi - lo) / (length - 2.0 * clearance);
    axis.lo = lo - pad;
    axis.hi = hi + pad;
}

/// Whether labelled ticks keep clear of each other: `extent(label)` is a label's size along the
/// axis (pixels), labels are centred on their ticks.
template <typename Extent>
bool labelsFit(const Axis& axis, const std::vector<Tick>& ticks, int scale, Extent extent)
{
    double previousEnd = -std::numeric_limits<double>::infinity();
    std::vector<std::pair<double, double>> spans;
    for (const Tick& t : ticks) {
        if (t.label.empty()) continue;
        const double centre = axis.pixelOf(t.value), half = 0.5 * extent(t.label);
        spans.emplace_back(std::min(centre - half, centre + half), centre + half);
    }
    std::sort(spans.begin(), spans.end());
    for (const auto& [begin, end] : spans) {
        if (begin < previousEnd + TICK_LABEL_GAP * scale) return false;
        previousEnd = end;
    }
    return true;
}

/// Ticks at multiples of a 1-2-5 step within the axis range, the first step whose labels fit
/// and whose ticks are MIN_TICK_SPACING apart. On a log axis the ticks sit at their log
/// positions (used when the range is too narrow for 1..9 x 10^k ticks).
template <typename Extent>
std::vector<Tick> linearTicks(const Axis& axis, int scale, Extent extent)
{
    const double a = axis.log ? std::pow(10.0, axis.lo) : axis.lo;
    const double b = axis.log ? std::pow(10.0, axis.hi) : axis.hi;
    std::vector<Tick> ticks;
    if (!(b > a) || !std::isfinite(b - a)) return ticks;
    const double base = std::pow(10.0, std::floor(std::log10((b - a) / 20.0)));
    for (int k = 0; k < 30; ++k) {
        const double step = base * std::pow(10.0, k / 3) * (k % 3 == 0 ? 1 : k % 3 == 1 ? 2 : 5);
        ticks.clear();
        const double first = std::ceil(a / step - 1e-9), last = std::floor(b / step + 1e-9);
        if (!(last - first < MAX_TICKS)) continue;
        for (int i = 0; i <= int(last - first); ++i) {
            const double value = (first + i == 0.0) ? 0.0 : (first + i) * step;
            if (axis.log && !(value > 0.0)) continue;
            ticks.push_back({value, true, linearLabel(value, step)});
        }
        const double spacing =
            ticks.size() > 1 ? std::abs(axis.pixelOf(ticks[1].value) - axis.pixelOf(ticks[0].value))
                             : axis.length();
        if (spacing >= MIN_TICK_SPACING * scale && labelsFit(axis, ticks, scale, extent)) break;
    }
    return ticks;
}

/// Ticks of a log axis: labelled decades (every one, or every 2nd, 3rd... where labels would
/// collide) with unlabelled 2 and 5 between them where there is room; ranges spanning less than
/// two decades get labels at 1, 2, 5 (or 1..9) x 10^k, and narrower ones linear ticks.
template <typename Extent>
std::vector<Tick> logTicks(const Axis& axis, int scale, Extent extent)
{
    const double eps = 1e-9;
    const int first = int(std::floor(axis.lo)), last = int(std::ceil(axis.hi));
    const auto inRange = [&](double logValue) {
        return logValue >= axis.lo - eps && logValue <= axis.hi + eps;
    };
    const double decadePixels = axis.length() / (axis.hi - axis.lo);
    std::vector<Tick> ticks;

    int decades = 0;
    for (int e = first; e <= last; ++e) decades += inRange(e) ? 1 : 0;
    if (decades >= 2) {
        const bool subticks = decadePixels >= MIN_DECADE_FOR_SUBTICKS * scale;
        for (int stride : {1, 2, 3, 4, 5, 10, 20, 50, 100}) {
            ticks.clear();
            for (int e = first; e <= last; ++e) {
                if (inRange(e)) {
                    // Unlabelled decades get a minor tick and no grid line.
                    const bool labelled = ((e % stride) + stride) % stride == 0;
                    ticks.push_back({std::pow(10.0, e), labelled, labelled ? logLabel(1, e) : ""});
                }
                for (int m : {2, 5}) {
                    if (subticks && inRange(e + std::log10(double(m)))) {
                        ticks.push_back({m * std::pow(10.0, e), false, ""});
                    }
                }
            }
            if (labelsFit(axis, ticks, scale, extent)) break;
        }
        return ticks;
    }
    // Under two decades: label 1, 2 and 5 x 10^k, else every 1..9 x 10^k, if two or more fit.
    for (const std::vector<int>& labelled :
         {std::vector<int>{1, 2, 5}, std::vector<int>{1, 2, 3, 4, 5, 6, 7, 8, 9}}) {
        ticks.clear();
        int count = 0;
        for (int e = first; e <= last; ++e) {
            for (int m = 1; m <= 9; ++m) {
                if (!inRange(e + std::log10(double(m)))) continue;
                const bool label = std::find(labelled.begin(), labelled.end(), m) != labelled.end();
                ticks.push_back({m * std::pow(10.0, e), label, label ? logLabel(m, e) : ""});
                count += label ? 1 : 0;
            }
        }
        if (count >= 2 && labelsFit(axis, ticks, scale, extent)) return ticks;
    }
    return linearTicks(axis, scale, extent);
}

template <typename Extent>
std::vector<Tick> makeTicks(const Axis& axis, int scale, Extent extent)
{
    return axis.log ? logTicks(axis, scale, extent) : linearTicks(axis, scale, extent);
}

/// How to name a point in a message: its label, else its index, with its series.
std::string pointName(const PlotPoint& p, std::size_t index)
{
    std::string name = p.label.empty() ? msg("point #", index) : msg("point '", p.label, "'");
    if (!p.series.empty()) name += msg(" of series '", p.series, "'");
    return name;
}

/// Check a coordinate for `axisName` ("x"/"y"): finite, and > 0 on a log axis.
void checkValue(double value, bool log, const char* axisName, const std::string& where,
                const std::string& what)
{
    if (!std::isfinite(value)) {
        throw ValueError(
            msg(where, ": ", what, " has ", axisName, " = ", value, ": expected a finite value"));
    }
    if (log && !(value > 0.0)) {
        throw ValueError(msg(where, ": ", what, " has ", axisName, " = ", value,
                             ": expected > 0 on a log ", axisName, " axis"));
    }
}

void checkSpec(const PlotSpec& spec, const std::string& where)
{
    if (spec.width < PlotSpec::MIN_WIDTH || spec.width > PlotSpec::MAX_SIDE) {
        throw ValueError(msg(where, ": width = ", spec.width, ": expected ", PlotSpec::MIN_WIDTH,
                             "..", PlotSpec::MAX_SIDE, " pixels"));
    }
    if (spec.height < PlotSpec::MIN_HEIGHT || spec.height > PlotSpec::MAX_SIDE) {
        throw ValueError(msg(where, ": height = ", spec.height, ": expected ", PlotSpec::MIN_HEIGHT,
                             "..", PlotSpec::MAX_SIDE, " pixels"));
    }
    if (spec.points.empty()) throw ValueError(msg(where, ": no points to plot"));
    for (std::size_t i = 0; i < spec.points.size(); ++i) {
        const PlotPoint& p = spec.points[i];
        checkValue(p.x, spec.logX, "x", where, pointName(p, i));
        checkValue(p.y, spec.logY, "y", where, pointName(p, i));
    }
}

/// Everything placed: the text scale, the axes box, both axes with their ticks, the series and
/// the legend.
struct Layout
{
    int scale = 1;             ///< text scale of titles, labels and the legend
    int smallScale = 1;        ///< text scale of point labels
    int pad = 6;               ///< outer margin and spacing unit (pixels)
    int tickLength = 3;        ///< major tick length (pixels), minor ticks 2/3 of it
    double markerRadius = 3.5; ///< marker radius (pixels)
    Box plot;                  ///< the axes box (its outline pixels)
    Axis x, y;
    std::vector<std::string> series;        ///< series names in order of first appearance
    std::vector<std::size_t> seriesOfPoint; ///< index into `series` for each point
    std::vector<std::size_t> front;         ///< Pareto front (empty unless markPareto)
    std::vector<std::string> legendNames;   ///< legend entries (truncated names)
    bool legendFront = false;               ///< legend ends with a "Pareto front" entry
    Box legend;                             ///< legend box, when there are entries
    int legendRow = 0;                      ///< legend row height (pixels)
};

Layout makeLayout(const PlotSpec& spec)
{
    Layout L;
    L.scale = std::clamp(std::min(spec.width / 400, spec.height / 280), 1, 4);
    L.smallScale = std::max(1, L.scale - 1);
    const int s = L.scale;
    L.pad = 6 * s;
    L.tickLength = 3 * s;
    L.markerRadius = 1.5 + 2.0 * s;
    const int textHeight = CAP_ROWS * s, lineHeight = GLYPH_ROWS * s;

    for (const PlotPoint& p : spec.points) {
        const auto at = std::find(L.series.begin(), L.series.end(), p.series);
        L.seriesOfPoint.push_back(std::size_t(at - L.series.begin()));
        if (at == L.series.end()) L.series.push_back(p.series);
    }
    if (spec.markPareto) L.front = paretoFront(spec.points);

    // Legend (right of the plot): one row per series, unless the only series has no name, and
    // one for the front.
    if (!(L.series.size() == 1 && L.series[0].empty())) {
        for (const std::string& name : L.series) {
            std::string shown = name.empty() ? "(no series)" : name;
            if (shown.size() > LEGEND_NAME_CHARS) {
                shown = shown.substr(0, LEGEND_NAME_CHARS - 2) + "..";
            }
            L.legendNames.push_back(shown);
        }
    }
    L.legendFront = !L.front.empty();
    const int legendRows = int(L.legendNames.size()) + (L.legendFront ? 1 : 0);
    L.legendRow = std::max(lineHeight + 2 * s, int(2.0 * L.markerRadius + 4 * s));
    int legendWidth = 0;
    if (legendRows > 0) {
        int nameWidth = textWidth("Pareto front", s);
        for (const std::string& name : L.legendNames) {
            nameWidth = std::max(nameWidth, textWidth(name, s));
        }
        legendWidth = 2 * L.pad + int(std::ceil(2.0 * L.markerRadius)) + 4 * s + nameWidth;
    }

    // Vertical layout: title, box, tick labels, x label.
    L.plot.top = L.pad + (spec.title.empty() ? textHeight / 2 : lineHeight + 2 * L.pad);
    L.plot.bottom = spec.height - 1 - L.pad - (spec.xLabel.empty() ? 0 : lineHeight + L.pad)
                    - lineHeight - 2 * s - L.tickLength;
    const double clearance = L.markerRadius + 4.0 * s;

    const auto dataRange = [&](bool log, bool isX) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const PlotPoint& p : spec.points) {
            const double v = log ? std::log10(isX ? p.x : p.y) : (isX ? p.x : p.y);
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        return std::make_pair(lo, hi);
    };

    // y first: its tick labels set the left margin, which sets the x axis length.
    L.y.log = spec.logY;
    L.y.pixelLo = L.plot.bottom;
    L.y.pixelHi = L.plot.top;
    const auto [ylo, yhi] = dataRange(spec.logY, false);
    padRange(L.y, ylo, yhi, L.y.length(), std::max(clearance, AXIS_MARGIN_FRACTION * L.y.length()));
    L.y.ticks = makeTicks(L.y, s, [&](const std::string&) { return double(textHeight); });
    int yLabelWidth = 0;
    for (const Tick& t : L.y.ticks) yLabelWidth = std::max(yLabelWidth, textWidth(t.label, s));

    // Absurdly long tick labels are cut on the left rather than squeezing the plot away.
    L.plot.left = std::min(spec.width / 3, L.pad + (spec.yLabel.empty() ? 0 : lineHeight + L.pad)
                                               + yLabelWidth + 2 * s + L.tickLength);
    // Right of the box: the legend, else room for half of the last x tick label.
    L.plot.right = spec.width - 1 - (legendRows > 0 ? legendWidth + 2 * L.pad : 3 * L.pad);
    // Never let a long legend squeeze the plot below half the image.
    L.plot.right = std::max(L.plot.right, L.plot.left + (spec.width - L.plot.left) / 2);
    L.x.log = spec.logX;
    L.x.pixelLo = L.plot.left;
    L.x.pixelHi = L.plot.right;
    const auto [xlo, xhi] = dataRange(spec.logX, true);
    padRange(L.x, xlo, xhi, L.x.length(), std::max(clearance, AXIS_MARGIN_FRACTION * L.x.length()));
    L.x.ticks =
        makeTicks(L.x, s, [&](const std::string& label) { return double(textWidth(label, s)); });

    if (legendRows > 0) {
        L.legend.left = L.plot.right + L.pad;
        L.legend.top = L.plot.top;
        L.legend.right = std::min(L.legend.left + legendWidth, spec.width - 1 - L.pad / 2);
        L.legend.bottom = L.legend.top + legendRows * L.legendRow + L.pad;
    }
    return L;
}

std::array<int, 2> pixelOf(const Layout& layout, double x, double y)
{
    return {int(std::lround(layout.x.pixelOf(x))), int(std::lround(layout.y.pixelOf(y)))};
}

/// Replace the temporary file's name in a message from writePng with the target's.
std::string namingTarget(std::string text, const std::string& tmp, const std::string& target)
{
    for (std::size_t at = text.find(tmp); at != std::string::npos; at = text.find(tmp, at)) {
        text.replace(at, tmp.size(), target);
        at += target.size();
    }
    return text;
}

/// Draw the whole plot.
Canvas render(const PlotSpec& spec, const Layout& L)
{
    Canvas canvas(spec.width, spec.height);
    const int s = L.scale, textHeight = CAP_ROWS * s, lineHeight = GLYPH_ROWS * s;
    const Box& box = L.plot;
    const double r = L.markerRadius;

    // Grid lines at the major ticks, inside the box.
    for (const Tick& t : L.x.ticks) {
        const int px = int(std::lround(L.x.pixelOf(t.value)));
        if (t.major && px > box.left && px < box.right) {
            canvas.fillRect(px, box.top + 1, px, box.bottom - 1, GRID);
        }
    }
    for (const Tick& t : L.y.ticks) {
        const int py = int(std::lround(L.y.pixelOf(t.value)));
        if (t.major && py > box.top && py < box.bottom) {
            canvas.fillRect(box.left + 1, py, box.right - 1, py, GRID);
        }
    }

    std::vector<std::array<int, 2>> at;
    std::vector<bool> onFront(spec.points.size(), false);
    for (const PlotPoint& p : spec.points) at.push_back(pixelOf(L, p.x, p.y));
    for (std::size_t i : L.front) onFront[i] = true;

    // The front: straight segments through its points in order of x, under the markers.
    const double frontWidth = 1.0 + 0.5 * s;
    for (std::size_t k = 1; k < L.front.size(); ++k) {
        const auto& a = at[L.front[k - 1]];
        const auto& b = at[L.front[k]];
        canvas.segment(a[0], a[1], b[0], b[1], frontWidth, FRONT);
    }

    // Labels of front points. No point lies below and left of a front point, and the front's
    // line leaves it up-left and down-right, so below-left is tried first; a label that would
    // cover a marker or another label, or leave the box, is moved or left out.
    const int ss = L.smallScale, offset = int(std::ceil(r)) + 2 * ss;
    std::vector<Box> taken;
    for (const auto& p : at) {
        const int reach = int(std::ceil(r)) + 1;
        taken.push_back({p[0] - reach, p[1] - reach, p[0] + reach, p[1] + reach});
    }
    const Box inner{box.left + 2, box.top + 2, box.right - 2, box.bottom - 2};
    for (std::size_t i : L.front) {
        const std::string& label = spec.points[i].label;
        if (label.empty()) continue;
        const int w = textWidth(label, ss), h = GLYPH_ROWS * ss;
        const int px = at[i][0], py = at[i][1];
        const Box candidates[] = {{px - offset - w, py + offset, px - offset, py + offset + h},
                                  {px + offset, py - offset - h, px + offset + w, py - offset},
                                  {px + offset, py + offset, px + offset + w, py + offset + h},
                                  {px - offset - w, py - offset - h, px - offset, py - offset}};
        for (const Box& c : candidates) {
            if (!c.inside(inner)) continue;
            const auto overlapsC = [&](const Box& t) { return t.overlaps(c); };
            if (std::any_of(taken.begin(), taken.end(), overlapsC)) continue;
            canvas.text(c.left, c.top, label, ss, TEXT);
            taken.push_back(c);
            break;
        }
    }

    // Markers, front points last so they stay on top; the front's are ringed.
    const double outline = std::max(1.0, 0.6 * s);
    const auto marker = [&](int cx, int cy, const Rgb& colour) {
        canvas.disc(cx, cy, r, shade(colour, OUTLINE_SHADE));
        canvas.disc(cx, cy, r - outline, colour);
    };
    const auto frontRing = [&](int cx, int cy) {
        canvas.ring(cx, cy, r + 0.5 * s, r + 1.5 * s, FRONT);
    };
    for (int pass = 0; pass < 2; ++pass) {
        for (std::size_t i = 0; i < spec.points.size(); ++i) {
            if (onFront[i] != (pass == 1)) continue;
            marker(at[i][0], at[i][1], plotSeriesColour(L.seriesOfPoint[i]));
            if (onFront[i]) frontRing(at[i][0], at[i][1]);
        }
    }

    // Box, ticks (outside the box) and tick labels.
    canvas.frameRect(box, AXES);
    for (const Tick& t : L.x.ticks) {
        const int px = int(std::lround(L.x.pixelOf(t.value)));
        const int length = t.major ? L.tickLength : (2 * L.tickLength) / 3;
        canvas.fillRect(px, box.bottom + 1, px, box.bottom + length, AXES);
        if (!t.label.empty()) {
            canvas.text(px - textWidth(t.label, s) / 2, box.bottom + L.tickLength + 2 * s, t.label,
                        s, TEXT);
        }
    }
    for (const Tick& t : L.y.ticks) {
        const int py = int(std::lround(L.y.pixelOf(t.value)));
        const int length = t.major ? L.tickLength : (2 * L.tickLength) / 3;
        canvas.fillRect(box.left - length, py, box.left - 1, py, AXES);
        if (!t.label.empty()) {
            canvas.text(box.left - L.tickLength - 2 * s - textWidth(t.label, s),
                        py - textHeight / 2, t.label, s, TEXT);
        }
    }

    // Axis labels: x centred under the tick labels, y turned to read upwards left of them.
    const int boxMiddleX = (box.left + box.right) / 2, boxMiddleY = (box.top + box.bottom) / 2;
    if (!spec.xLabel.empty()) {
        canvas.text(boxMiddleX - textWidth(spec.xLabel, s) / 2,
                    box.bottom + L.tickLength + 2 * s + lineHeight + L.pad, spec.xLabel, s, TEXT);
    }
    if (!spec.yLabel.empty()) {
        canvas.text(L.pad, boxMiddleY + textWidth(spec.yLabel, s) / 2, spec.yLabel, s, TEXT, true);
    }
    // Title, centred over the box and kept on the image, drawn twice one pixel apart (bold).
    if (!spec.title.empty()) {
        const int w = textWidth(spec.title, s) + 1;
        const int left =
            std::clamp(boxMiddleX - w / 2, L.pad, std::max(L.pad, spec.width - L.pad - w));
        canvas.text(left, L.pad, spec.title, s, TEXT);
        canvas.text(left + 1, L.pad, spec.title, s, TEXT);
    }

    // Legend: a marker and the name for each series, then the front's line and ring.
    if (L.legend.bottom > L.legend.top) {
        canvas.fillRect(L.legend.left, L.legend.top, L.legend.right, L.legend.bottom, WHITE);
        canvas.frameRect(L.legend, LEGEND_EDGE);
        const int cx = L.legend.left + L.pad + int(std::ceil(r));
        const int textLeft = cx + int(std::ceil(r)) + 4 * s;
        const auto rowCentre = [&](std::size_t row) {
            return L.legend.top + L.pad / 2 + int(row) * L.legendRow + L.legendRow / 2;
        };
        for (std::size_t k = 0; k < L.legendNames.size(); ++k) {
            const int cy = rowCentre(k);
            marker(cx, cy, plotSeriesColour(k));
            canvas.text(textLeft, cy - textHeight / 2, L.legendNames[k], s, TEXT);
        }
        if (L.legendFront) {
            const int cy = rowCentre(L.legendNames.size());
            const double reach = r + 2.0 * s;
            canvas.segment(cx - reach, cy, cx + reach, cy, frontWidth, FRONT);
            canvas.disc(cx, cy, r + 0.5 * s, WHITE);
            frontRing(cx, cy);
            canvas.text(textLeft + s, cy - textHeight / 2, "Pareto front", s, TEXT);
        }
    }
    return canvas;
}

} // namespace

std::vector<std::size_t> paretoFront(const std::vector<PlotPoint>& points)
{
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (std::isfinite(points[i].x) && std::isfinite(points[i].y)) order.push_back(i);
    }
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        const PlotPoint &pa = points[a], &pb = points[b];
        return pa.x != pb.x ? pa.x < pb.x : pa.y != pb.y ? pa.y < pb.y : a < b;
    });
    // In (x, y) order, every point before a group of identical points has x < or y < than the
    // group with the other coordinate <=, so it beats the group exactly when its y is <= the
    // group's y: the group is on the front when its y is below all earlier ones.
    std::vector<std::size_t> front;
    double lowestEarlierY = std::numeric_limits<double>::infinity();
    for (std::size_t begin = 0; begin < order.size();) {
        const PlotPoint& p = points[order[begin]];
        std::size_t end = begin + 1;
        while (end < order.size() && points[order[end]].x == p.x && points[order[end]].y == p.y) {
            ++end;
        }
        if (p.y < lowestEarlierY) {
            front.insert(front.end(), order.begin() + begin, order.begin() + end);
        }
        lowestEarlierY = std::min(lowestEarlierY, p.y);
        begin = end;
    }
    return front;
}

void writePlotPng(const std::string& path, const PlotSpec& spec)
{
    const std::string where = msg("plot '", path, "'");
    if (extensionOf(path) != ".png") {
        throw ValueError(msg(where, ": expected a file name ending in .png"));
    }
    checkSpec(spec, where);
    const std::vector<float> rgba = render(spec, makeLayout(spec)).linearRgba();
    writeAtomically(path, [&](const std::string& tmp) {
        try {
            writePng(tmp, spec.width, spec.height, rgba);
        } catch (const IoError& e) {
            throw IoError(namingTarget(e.what(), tmp, path));
        }
    });
}

std::array<int, 2> plotPixelOf(const PlotSpec& spec, double x, double y)
{
    checkSpec(spec, "plot");
    checkValue(x, spec.logX, "x", "plot", "the pixel asked for");
    checkValue(y, spec.logY, "y", "plot", "the pixel asked for");
    return pixelOf(makeLayout(spec), x, y);
}

std::array<std::uint8_t, 3> plotSeriesColour(std::size_t seriesIndex)
{
    return PALETTE[seriesIndex % PALETTE_SIZE];
}

} // namespace vdbio
} // namespace ghostfx
