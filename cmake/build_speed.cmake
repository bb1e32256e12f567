# The cold build's cost, decided in one place (issue 37; docs/BENCHMARKS.md, "The cold build").
# Included last from the top-level CMakeLists.txt, when every target exists.
#
# 1. Precompiled headers. Each file of a target parsed the same third-party headers again:
#    nlohmann/json (~2.5 s of CPU), GoogleTest (~2.3 s), Eigen/Dense (~1.8 s), CLI11 (~3 s), fmt
#    and <chrono> (~1 s each), in up to 70 files a target. A target of many files that include
#    them parses them once into its precompiled header (GCC and the fuzz build's clang alike).
#    Only headers most of the target's files already include, with the target's own flags;
#    toml++ in none (twelve files read TOML, the others only name TomlView). Measured per file
#    (docs/BENCHMARKS.md): station_store -13 %, its header's 13.5 s included. compensation has
#    none: its time is Eigen's instantiations (JacobiSVD, QR), which a precompiled header does
#    not hold; drivers and sim_devices none either (fmt and <chrono> alone: within the noise).
#    Off with -DCMAKE_DISABLE_PRECOMPILE_HEADERS=ON (CMake's own switch).
set(_station_pch_core <chrono> <fmt/format.h> <nlohmann/json.hpp> <Eigen/Dense>)

function(station_pch target)
  if(TARGET ${target})
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()

# Built here without a new warning: store and test_drivers. In the other targets a precompiled
# header changes GCC 12's inlining enough for its -Warray-bounds false positive on
# `std::string(...) + "literal"` to appear (tests/compensation/test_allan_stable32.cpp:26 with
# one; without, none), and they were not all built with one yet: STATION_PCH_WIDE=ON adds them
# (an estimated -13 % for the rooms, more for the tests) once a whole build shows no new warning.
option(STATION_PCH_WIDE "precompiled headers for every room and test program too" OFF)
station_pch(station_store ${_station_pch_core})
station_pch(test_drivers <chrono> <gtest/gtest.h> <fmt/format.h>)
if(STATION_PCH_WIDE)
  foreach(room IN ITEMS parts acceptance release report fleet daemon session http)
    station_pch(station_${room} ${_station_pch_core})
  endforeach()
  station_pch(station_cli ${_station_pch_core} <CLI/CLI.hpp>)
  station_pch(station_bench ${_station_pch_core} <benchmark/benchmark.h>)
endif()

# 2. The test programs' debug information: line tables (-g1), not the full -g of RelWithDebInfo.
#    A test program is neither shipped nor debugged in CI; a failure names its file and line, a
#    crash's backtrace (and ASan's report) still has functions, files and lines. Full DWARF for
#    the test files was about a third of their compile time (-ftime-report: "phase opt and
#    generate" 22 s with -g, 11 s without, of 48 s for tests/station/test_acceptance_steps.cpp).
#    The libraries and programs under test keep -g: `station` and `simrig` are built as before.
#    To step through a test with its locals: -DSTATION_TEST_DEBUG_INFO=-g.
set(STATION_TEST_DEBUG_INFO -g1 CACHE STRING
    "debug information of the test programs' own files in RelWithDebInfo (-g1: line tables)")
foreach(area IN ITEMS compensation drivers calibration fleet station)
  if(TARGET test_${area})
    target_compile_options(test_${area} PRIVATE
                           $<$<CONFIG:RelWithDebInfo>:${STATION_TEST_DEBUG_INFO}>)
  endif()
endforeach()
if(STATION_PCH_WIDE)
  set(_station_test_pch <chrono> <gtest/gtest.h>)
  station_pch(test_compensation ${_station_test_pch} <Eigen/Dense>)
  station_pch(test_calibration ${_station_test_pch} <Eigen/Dense>)
  station_pch(test_fleet ${_station_test_pch} <fmt/format.h> <nlohmann/json.hpp> <Eigen/Dense>)
  station_pch(test_station ${_station_test_pch} <fmt/format.h> <nlohmann/json.hpp> <Eigen/Dense>)
endif()
