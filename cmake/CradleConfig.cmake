# find_package(Cradle) after `make install`: Cradle's static libraries as imported targets.
#   Cradle::cradle_lib        every room (core ... train: every env family, learner and run)
#   Cradle::cradle_<room>     one room and the rooms below it (e.g. cradle_envs: every env family
#                             behind the Env interface, without LibTorch)
# Headers are included as in the source tree ("core/config.h", "envs/env.h"). The libraries link
# against the same Debian packages as the build, found here again.
include(CMakeFindDependencyMacro)
find_dependency(yaml-cpp)
find_dependency(nlohmann_json)
find_dependency(ZLIB)
find_dependency(Torch)
find_dependency(box2d)
find_dependency(Eigen3 NO_MODULE)
find_dependency(PkgConfig)
pkg_check_modules(STB REQUIRED IMPORTED_TARGET stb)
pkg_check_modules(LIBZIP REQUIRED IMPORTED_TARGET libzip)
pkg_check_modules(FFMPEG REQUIRED IMPORTED_TARGET libavcodec libavformat libswscale libavutil)
pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo)
include(${CMAKE_CURRENT_LIST_DIR}/CradleTargets.cmake)
