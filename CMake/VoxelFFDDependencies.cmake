# What the VTK modules need besides VTK, found the same way by the VTK build (CMakeLists.txt) and by the
# ParaView plugin's build (ParaView/CMakeLists.txt), which compiles the modules again against ParaView's VTK.

# The CUDA backend is built when a CUDA compiler is found (this project's machines have CUDA 13 at
# /usr/local/cuda but no GPU); without one everything else builds and passes as is.
option(VOXELFFD_ENABLE_CUDA "Build the CUDA backend when a CUDA compiler is found" ON)
set(VOXELFFD_HAS_CUDA OFF)
if (VOXELFFD_ENABLE_CUDA)
  include(CheckLanguage)
  check_language(CUDA)
  if (CMAKE_CUDA_COMPILER)
    if (NOT CMAKE_CUDA_HOST_COMPILER)
      set(CMAKE_CUDA_HOST_COMPILER "${CMAKE_CXX_COMPILER}") # the same libstdc++ as the rest of the build
    endif ()
    if (NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      set(CMAKE_CUDA_ARCHITECTURES 90) # H100/H200; "native" fails on a machine without a GPU
    endif ()
    enable_language(CUDA)
    set(VOXELFFD_HAS_CUDA ON)
  endif ()
endif ()
message(STATUS "VoxelFFD CUDA backend: ${VOXELFFD_HAS_CUDA}")

list(APPEND CMAKE_MODULE_PATH "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB")
find_package(OpenVDB REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Qhull REQUIRED) # convex hulls of vtkFFDBuildTetrahedralLattice (reentrant C library, qhull_r)
