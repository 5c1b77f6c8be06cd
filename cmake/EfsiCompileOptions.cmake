# Warnings and tuning shared by every target through the efsi_options interface.
add_library(efsi_options INTERFACE)
# -ffp-contract=off: a point must round the same in the vector body and the scalar
# remainder of a loop, or results would depend on where a box starts (async halo mode,
# decomposition); -fno-math-errno lets sqrt vectorise.
target_compile_options(efsi_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -ffp-contract=off -fno-math-errno -fopenmp-simd
  $<$<CONFIG:Release,RelWithDebInfo>:-O3>)
if(EFSI_NATIVE)
  target_compile_options(efsi_options INTERFACE -march=native)
endif()
# -O1 under the sanitizers: at -O0 the solver tests run for tens of minutes.
if(EFSI_SANITIZE)
  target_compile_options(efsi_options INTERFACE
    -O1 -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(efsi_options INTERFACE -fsanitize=address,undefined)
endif()
