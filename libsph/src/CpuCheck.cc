/// @file   CpuCheck.cc
/// @brief  A build made for AVX2 (CMake option GHOSTFX_AVX2) stops with a message on a
///         processor without it, instead of dying on the first illegal instruction.
/// @details This file alone is compiled without AVX (libsph/CMakeLists.txt). The check runs when
///          libghostfx_sph is loaded: before the library's other static initialisers
///          (constructor priority 101) and before every library and program that links it,
///          the ghostfx command, the Python module and the tests included. (In a static
///          libghostfx_sph.a nothing references this object, so a static link would leave it
///          out; ghostfx builds shared libraries, and Debian's FindOpenVDB insists on them.)
#if defined(GHOSTFX_AVX2) && defined(__x86_64__)
#include <cstdio>
#include <cstdlib>

namespace {

__attribute__((constructor(101))) void requireAvx2()
{
    __builtin_cpu_init(); // needed before __builtin_cpu_supports in a constructor
    if (__builtin_cpu_supports("avx2")) return;
    std::fputs("ghostfx: this build uses AVX2 instructions (CMake option GHOSTFX_AVX2=ON) and "
               "this processor has none; rebuild ghostfx with -DGHOSTFX_AVX2=OFF\n",
               stderr);
    std::_Exit(EXIT_FAILURE);
}

} // namespace
#endif
