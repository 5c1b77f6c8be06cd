# Warnings and tuning shared by every target through the efsi_options interface.
add_library(efsi_options INTERFACE)
# -ffp-contract=off: a point must round the same in the vector body and the scalar
# remainder of a loop, or results would depend on where a box starts (async halo mode,
# decomposition); the kernels that want a fused multiply-add ask for it (mul_add.hpp).
# -fno-math-errno lets sqrt and fma vectorise.
target_compile_options(efsi_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -ffp-contract=off -fno-math-errno -fopenmp-simd
  $<$<CONFIG:Release,RelWithDebInfo>:-O3>)
if(EFSI_SIMGRID)
  target_compile_definitions(efsi_options INTERFACE EFSI_SIMGRID=1)
endif()
# EFSI_ARCH fixes the target instead (the counted preset's x86-64-v3: AVX2, which Valgrind
# executes, and the same instructions whichever CPU builds it).
set(EFSI_ARCH "" CACHE STRING "Target instruction set (-march=EFSI_ARCH); empty: EFSI_NATIVE decides")
if(EFSI_ARCH)
  target_compile_options(efsi_options INTERFACE -march=${EFSI_ARCH})
  set(EFSI_TARGET_NAME ${EFSI_ARCH})
elseif(EFSI_NATIVE)
  target_compile_options(efsi_options INTERFACE -march=native)
  set(EFSI_TARGET_NAME native)
else()
  set(EFSI_TARGET_NAME generic)
endif()
# GCC keeps loops at 256-bit vectors on AVX-512 targets unless told otherwise; the WENO5
# and stretching loops are compute-bound and gain from the full width (README, "Vector
# width").  A target without AVX-512 (x86-64-v3, Zen 3) is not affected, and with
# -ffp-contract=off (and std::fma where asked for) the width moves no bit of any result.
set(EFSI_VECTOR_WIDTH 512 CACHE STRING "Preferred vector width in bits (-mprefer-vector-width): 512, 256, 128 or none")
set(_efsi_widths 512 256 128 none)
if(NOT EFSI_VECTOR_WIDTH IN_LIST _efsi_widths)
  message(FATAL_ERROR "EFSI_VECTOR_WIDTH=${EFSI_VECTOR_WIDTH} is not one of 512, 256, 128, none")
endif()
target_compile_options(efsi_options INTERFACE -mprefer-vector-width=${EFSI_VECTOR_WIDTH})
# The build configuration in one word, for the counted gate's choice of baseline
# (results/microbench/baseline/counts-<this>.json): target, compiler, build type.
string(TOLOWER "${EFSI_TARGET_NAME}-${CMAKE_CXX_COMPILER_ID}-${CMAKE_CXX_COMPILER_VERSION}-${CMAKE_BUILD_TYPE}"
       EFSI_BUILD_CONFIG)
# -O1 under the sanitizers: at -O0 the solver tests run for tens of minutes.
if(EFSI_SANITIZE)
  target_compile_options(efsi_options INTERFACE
    -O1 -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(efsi_options INTERFACE -fsanitize=address,undefined)
endif()
