#pragma once
// The simulation build only (drivers/CMakeLists.txt includes it first in every driver
// source): smpicxx force-includes SMPI's helpers, which define exit(x) as a macro, and that
// macro breaks CLI11's member App::exit(error, out, err).  CLI11 is read with it set aside.
#pragma push_macro("exit")
#undef exit
#include <CLI/CLI.hpp>
#pragma pop_macro("exit")
