# Shared compile flags: every rocklab target links rocklab_warnings.
add_library(rocklab_warnings INTERFACE)
target_compile_options(rocklab_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wno-unknown-pragmas
  # GCC 12 false positive on std::string concatenation (GCC bug 105329).
  $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict>
  # Determinism: no fused multiply-add contraction, so results do not depend on
  # which code path the compiler picked for a loop.
  -ffp-contract=off
  # sqrt without the errno branch: the results are the same, the hot loop shorter.
  -fno-math-errno)
if(ROCKLAB_WERROR)
  target_compile_options(rocklab_warnings INTERFACE -Werror)
endif()
if(ROCKLAB_NATIVE)
  target_compile_options(rocklab_warnings INTERFACE -march=native)
endif()
if(ROCKLAB_SANITIZE)
  target_compile_options(rocklab_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer)
  target_link_options(rocklab_warnings INTERFACE -fsanitize=address,undefined)
endif()
if(ROCKLAB_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "ROCKLAB_FUZZ=ON needs clang (cmake --preset asan-clang)")
  endif()
  # Coverage feedback for libFuzzer in every rocklab library; the fuzz targets add
  # -fsanitize=fuzzer (the libFuzzer main) themselves.
  target_compile_options(rocklab_warnings INTERFACE -fsanitize=fuzzer-no-link)
  target_link_options(rocklab_warnings INTERFACE -fsanitize=fuzzer-no-link)
endif()
