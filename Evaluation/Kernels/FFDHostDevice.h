// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDHostDevice.h
 * @brief Marks the VTK-free kernel functions callable from host and CUDA device code.
 *
 * Everything under Evaluation/Kernels is plain C++17 with no VTK, OpenVDB, TBB or Eigen, so that the CPU path
 * (inside vtkSMPTools::For) and the CUDA path compile the very same per-point functions.
 */
#ifndef FFDHostDevice_h
#define FFDHostDevice_h

#if defined(__CUDACC__)
#define FFD_HOST_DEVICE __host__ __device__
#else
#define FFD_HOST_DEVICE
#endif

#define FFD_INLINE FFD_HOST_DEVICE inline

// Unrolls the loop that follows in device code, where an array indexed by a run-time loop counter would live in
// local memory rather than registers; host compilers unroll such short loops by themselves.
#if defined(__CUDA_ARCH__)
#define FFD_UNROLL _Pragma("unroll")
#else
#define FFD_UNROLL
#endif

#endif
