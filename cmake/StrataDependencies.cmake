# Every external package is found here, once. The Debian 12 quirks are wrapped so that
# targets only ever link clean imported targets (strata::...).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)

# GDAL 3.6 ships a CMake config.
find_package(GDAL CONFIG REQUIRED)

# GeographicLib 2.1 on Debian has no imported target: wrap the pkg-config module.
pkg_check_modules(GEOGRAPHICLIB REQUIRED IMPORTED_TARGET geographiclib)
add_library(strata::geographiclib ALIAS PkgConfig::GEOGRAPHICLIB)

# OpenImageIO's exported target lists /usr/include/opencv4 in its interface include
# directories, which does not exist unless OpenCV's headers are installed: drop that entry.
find_package(OpenImageIO CONFIG REQUIRED)
get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
if(_oiio_inc)
  list(FILTER _oiio_inc EXCLUDE REGEX "opencv4")
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_inc}")
endif()
get_target_property(_oiio_util_inc OpenImageIO::OpenImageIO_Util INTERFACE_INCLUDE_DIRECTORIES)
if(_oiio_util_inc)
  list(FILTER _oiio_util_inc EXCLUDE REGEX "opencv4")
  set_target_properties(OpenImageIO::OpenImageIO_Util PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_util_inc}")
endif()
find_package(OpenEXR CONFIG REQUIRED)

# GL: libepoxy resolves GL and EGL entry points (no X server needed for EGL).
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)  # headers; libepoxy loads libEGL (gl/CMakeLists.txt)
find_package(glfw3 CONFIG REQUIRED)
find_package(glm CONFIG REQUIRED)

find_package(CLI11 CONFIG REQUIRED)
find_package(tomlplusplus CONFIG QUIET)
if(NOT tomlplusplus_FOUND)
  pkg_check_modules(TOMLPP REQUIRED IMPORTED_TARGET tomlplusplus)
  add_library(tomlplusplus::tomlplusplus ALIAS PkgConfig::TOMLPP)
endif()

if(STRATA_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
  include(GoogleTest)
endif()
if(STRATA_BUILD_BENCH)
  find_package(benchmark CONFIG REQUIRED)
endif()

# OpenMP (GCC's libgomp): the CPU solver's threads.
find_package(OpenMP REQUIRED COMPONENTS CXX)

# MPI (Open MPI on Debian) for distributed runs: MPI::MPI_CXX (the C API from C++); mpirun is
# MPIEXEC_EXECUTABLE, which the multi-rank tests run under.
find_package(MPI REQUIRED COMPONENTS CXX)
# Open MPI refuses more ranks than cores unless told to oversubscribe (tests run 4 ranks on 2).
set(STRATA_MPIEXEC_FLAGS ${MPIEXEC_PREFLAGS})
execute_process(COMMAND ${MPIEXEC_EXECUTABLE} --version OUTPUT_VARIABLE _mpiexec_version ERROR_QUIET)
if(_mpiexec_version MATCHES "Open MPI|OpenRTE")
  list(APPEND STRATA_MPIEXEC_FLAGS --oversubscribe)
endif()
