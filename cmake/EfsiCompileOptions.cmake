# Warnings and tuning shared by every target through the efsi_options interface.
add_library(efsi_options INTERFACE)
target_compile_options(efsi_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
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
