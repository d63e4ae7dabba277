# Project-wide warning flags, applied per target with vessel_set_warnings(target).
function(vessel_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                           -Wno-sign-conversion)
endfunction()
