/// @file   PngFile.h
/// @brief  Private to vdbio: 8-bit RGBA PNG writing (zlib), for previews a README can show.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// Write `rgba` (row-major from the top row, 4 floats per pixel, linear colour, straight alpha)
/// to `path` as an 8-bit sRGB PNG. Plain write; the caller makes it atomic.
void writePng(const std::string& path, int width, int height, const std::vector<float>& rgba);

/// Read back an 8-bit RGBA PNG written by writePng (filter type 0 only): for tests.
std::vector<std::uint8_t> readPngRgba8(const std::string& path, int& width, int& height);

} // namespace vdbio
} // namespace ghostfx
