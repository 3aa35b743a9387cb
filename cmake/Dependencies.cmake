# Every third-party library comes from Debian 12 packages (see README,
# "Dependencies"); nothing is vendored or downloaded. Each workaround below
# says the fact behind it beside it.
find_package(PkgConfig REQUIRED)
find_package(ZLIB REQUIRED)

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(assimp REQUIRED)
find_package(embree 3 REQUIRED)

# OpenVDB ships a find module (not a config package) in its cmake folder.
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB
     /usr/lib/cmake/OpenVDB /usr/local/lib/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)

# OpenImageIO's imported target names /usr/include/opencv4, which only exists
# when OpenCV's headers are installed; drop entries that do not exist.
find_package(OpenImageIO REQUIRED)
get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
if(_oiio_inc)
  set(_oiio_keep)
  foreach(_dir IN LISTS _oiio_inc)
    if(EXISTS "${_dir}" OR _dir MATCHES "^\\$<")
      list(APPEND _oiio_keep "${_dir}")
    endif()
  endforeach()
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES
                        INTERFACE_INCLUDE_DIRECTORIES "${_oiio_keep}")
endif()

# Bullet's own BulletConfig.cmake gives relative include paths and no targets;
# the pkg-config module is reliable. Float precision (the "bullet" module).
pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
pkg_check_modules(GLFW REQUIRED IMPORTED_TARGET glfw3)  # the interactive viewer's window
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)

if(HAIRPIPE_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
