/// @file   Readers.h
/// @brief  The ghostfx module's file readers: read_points, read_volume, read_stats and
///         read_checkpoint (Readers.cc), bound by PYBIND11_MODULE in module.cc.
#pragma once

#include <pybind11/pybind11.h>

/// Add the readers (and their Volume class) to the module `m`.
void bindReaders(pybind11::module_& m);
