// The haze kernels compiled for AVX2 (haze_kernels.h); CMake builds this file
// with -mavx2 on x86-64 only. Nothing here runs unless hazeKernels() found
// AVX2 on the CPU (the table below is constant data: no code runs to make it).
#ifdef __AVX2__
#include "runtime/engine/haze_kernels_impl.h"

namespace vista {

namespace {
constexpr HazeKernels kAvx2{hazeWindowKernel, hazeDepthKernel};
}  // namespace

const HazeKernels* hazeKernelsAvx2Table() { return &kAvx2; }

}  // namespace vista
#endif
