/// @file   ReadersDetail.h
/// @brief  What the point and volume readers (Readers.cc, VolumeReader.cc) share: value-type
///         traits, column making and grid look-up in a file.
#pragma once

#include <ghostfx/vdbio/Readers.h>

#include <openvdb/openvdb.h>

#include <cstdint>
#include <string>
#include <type_traits>

namespace ghostfx {
namespace vdbio {
namespace detail {

template <typename T>
struct Tag
{
    using type = T;
};

/// Element type and component count of an attribute or voxel value type.
template <typename V>
struct ValueTraits
{
    using Element = V;
    static constexpr int components = 1;
    static Element get(const V& v, int) { return v; }
};
template <typename E>
struct ValueTraits<openvdb::math::Vec3<E>>
{
    using Element = E;
    static constexpr int components = 3;
    static Element get(const openvdb::math::Vec3<E>& v, int c) { return v[c]; }
};

template <typename E>
constexpr ScalarType scalarOf()
{
    if constexpr (std::is_same_v<E, bool>) return ScalarType::Bool;
    else if constexpr (std::is_same_v<E, std::int8_t>) return ScalarType::Int8;
    else if constexpr (std::is_same_v<E, std::int16_t>) return ScalarType::Int16;
    else if constexpr (std::is_same_v<E, std::int32_t>) return ScalarType::Int32;
    else if constexpr (std::is_same_v<E, std::int64_t>) return ScalarType::Int64;
    else if constexpr (std::is_same_v<E, std::uint8_t>) return ScalarType::UInt8;
    else if constexpr (std::is_same_v<E, std::uint16_t>) return ScalarType::UInt16;
    else if constexpr (std::is_same_v<E, std::uint32_t>) return ScalarType::UInt32;
    else if constexpr (std::is_same_v<E, std::uint64_t>) return ScalarType::UInt64;
    else if constexpr (std::is_same_v<E, float>) return ScalarType::Float32;
    else {
        static_assert(std::is_same_v<E, double>, "unsupported element type");
        return ScalarType::Float64;
    }
}

/// A column of `rows` zeroed values.
Column makeColumn(std::string name, std::string storedType, ScalarType scalar, int components,
                  std::size_t rows);

/// The grid named `grid` of `file`, or with an empty name the first grid `accept` takes
/// (`wanted` names such a grid in the error: "point grid"). IoError for a missing or
/// unreadable file, GridError naming the file's grids when the grid is not there.
openvdb::GridBase::Ptr readGridOf(const std::string& file, const std::string& grid,
                                  const std::string& context, const char* wanted,
                                  bool (*accept)(const openvdb::GridBase&));

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
