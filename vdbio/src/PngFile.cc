/// @file   PngFile.cc
/// @brief  Minimal PNG (ISO/IEC 15948) writer: IHDR, one zlib-compressed IDAT of unfiltered
///         RGBA8 scanlines, IEND; chunk CRCs from zlib's crc32.
#include "PngFile.h"

#include <ghostfx/sph/Exceptions.h>

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

namespace ghostfx {
namespace vdbio {

namespace {

const unsigned char SIGNATURE[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

void putU32(std::vector<unsigned char>& out, std::uint32_t v)
{
    for (int shift = 24; shift >= 0; shift -= 8)
        out.push_back((unsigned char)((v >> shift) & 0xff));
}

std::uint32_t getU32(const unsigned char* p)
{
    return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8)
           | p[3];
}

void chunk(std::vector<unsigned char>& out, const char type[4],
           const std::vector<unsigned char>& data)
{
    putU32(out, std::uint32_t(data.size()));
    const std::size_t start = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    const uLong crc = crc32(0L, out.data() + start, uInt(out.size() - start));
    putU32(out, std::uint32_t(crc));
}

/// Linear [0, 1] to the sRGB transfer curve, 8 bits.
unsigned char toSrgb8(float linear)
{
    const float c = std::clamp(linear, 0.0f, 1.0f);
    const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)std::lround(s * 255.0f);
}

} // namespace

void writePng(const std::string& path, int width, int height, const std::vector<float>& rgba)
{
    if (width < 1 || height < 1 || rgba.size() != std::size_t(width) * std::size_t(height) * 4) {
        throw ValueError(msg("PNG '", path, "': ", width, " x ", height, " image with ",
                             rgba.size(), " values: expected width x height x 4"));
    }
    // Scanlines, each led by filter type 0 (none).
    std::vector<unsigned char> raw;
    raw.reserve(std::size_t(height) * (std::size_t(width) * 4 + 1));
    for (int y = 0; y < height; ++y) {
        raw.push_back(0);
        for (int x = 0; x < width; ++x) {
            const float* p = &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
            raw.push_back(toSrgb8(p[0]));
            raw.push_back(toSrgb8(p[1]));
            raw.push_back(toSrgb8(p[2]));
            raw.push_back((unsigned char)std::lround(std::clamp(p[3], 0.0f, 1.0f) * 255.0f));
        }
    }
    uLongf packedSize = compressBound(uLong(raw.size()));
    std::vector<unsigned char> packed(packedSize);
    if (compress2(packed.data(), &packedSize, raw.data(), uLong(raw.size()), 6) != Z_OK) {
        throw IoError(msg("PNG '", path, "': zlib compression failed"));
    }
    packed.resize(packedSize);

    std::vector<unsigned char> file(SIGNATURE, SIGNATURE + 8);
    std::vector<unsigned char> header;
    putU32(header, std::uint32_t(width));
    putU32(header, std::uint32_t(height));
    header.insert(header.end(), {8, 6, 0, 0, 0}); // 8 bits, RGBA, deflate, filter 0, no interlace
    chunk(file, "IHDR", header);
    chunk(file, "IDAT", packed);
    chunk(file, "IEND", {});

    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(file.data()), std::streamsize(file.size()));
    if (!out) throw IoError(msg("PNG '", path, "': cannot write"));
}

std::vector<std::uint8_t> readPngRgba8(const std::string& path, int& width, int& height)
{
    std::ifstream in(path, std::ios::binary);
    const std::vector<unsigned char> bytes{std::istreambuf_iterator<char>(in),
                                           std::istreambuf_iterator<char>()};
    if (bytes.size() < 8 || std::memcmp(bytes.data(), SIGNATURE, 8) != 0) {
        throw IoError(msg("PNG '", path, "': not a PNG file"));
    }
    std::vector<unsigned char> packed;
    width = height = 0;
    for (std::size_t at = 8; at + 12 <= bytes.size();) {
        const std::uint32_t length = getU32(&bytes[at]);
        const std::string type(reinterpret_cast<const char*>(&bytes[at + 4]), 4);
        const unsigned char* data = &bytes[at + 8];
        if (type == "IHDR") {
            width = int(getU32(data));
            height = int(getU32(data + 4));
        } else if (type == "IDAT") {
            packed.insert(packed.end(), data, data + length);
        }
        at += 12 + length;
    }
    std::vector<unsigned char> raw(std::size_t(height) * (std::size_t(width) * 4 + 1));
    uLongf rawSize = uLongf(raw.size());
    if (width < 1
        || uncompress(raw.data(), &rawSize, packed.data(), uLong(packed.size())) != Z_OK) {
        throw IoError(msg("PNG '", path, "': cannot decode"));
    }
    std::vector<std::uint8_t> rgba;
    rgba.reserve(std::size_t(width) * std::size_t(height) * 4);
    for (int y = 0; y < height; ++y) {
        const unsigned char* row = &raw[std::size_t(y) * (std::size_t(width) * 4 + 1)];
        if (row[0] != 0)
            throw IoError(msg("PNG '", path, "': filter type ", int(row[0]), " not supported"));
        rgba.insert(rgba.end(), row + 1, row + 1 + std::size_t(width) * 4);
    }
    return rgba;
}

} // namespace vdbio
} // namespace ghostfx
