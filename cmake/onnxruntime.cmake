# Provides the imported target onnxruntime::onnxruntime (ONNX Runtime's C/C++ API) for
# AVATARMAP_WITH_ONNX. Included from the top-level CMakeLists.txt.
#
# Looked for in this order:
#  1. an installed ONNX Runtime package config (find_package(onnxruntime CONFIG)), as ONNX
#     Runtime's own CMake install provides: pass -Donnxruntime_DIR=... or CMAKE_PREFIX_PATH;
#  2. a plain prefix with include/onnxruntime_c_api.h and lib/libonnxruntime.so:
#     AVATARMAP_ONNXRUNTIME_DIR, default $ENV{AVATARMAP_ONNXRUNTIME_DIR}, else the folder that
#     scripts/fetch_onnxruntime.sh fills (.cache/avatarmap/onnxruntime). An official release
#     archive (onnxruntime-linux-x64-<version>.tgz) unpacked anywhere has this layout too.
#
# Sets ONNXRuntime_API_VERSION (ORT_API_VERSION of the headers) when the headers are found.
# Fails at configure time, naming scripts/fetch_onnxruntime.sh, when neither is found.

find_package(onnxruntime CONFIG QUIET)

if(onnxruntime_FOUND AND TARGET onnxruntime::onnxruntime)
  message(STATUS "ONNX Runtime: package config ${onnxruntime_DIR} (${onnxruntime_VERSION})")
else()
  if(DEFINED ENV{AVATARMAP_ONNXRUNTIME_DIR})
    set(_avm_ort_default "$ENV{AVATARMAP_ONNXRUNTIME_DIR}")
  else()
    set(_avm_ort_default "${PROJECT_SOURCE_DIR}/.cache/avatarmap/onnxruntime")
  endif()
  set(AVATARMAP_ONNXRUNTIME_DIR "${_avm_ort_default}" CACHE PATH
      "ONNX Runtime prefix (include/onnxruntime_c_api.h, lib/libonnxruntime.so)")

  find_path(AVATARMAP_ONNXRUNTIME_INCLUDE_DIR onnxruntime_c_api.h
            PATHS "${AVATARMAP_ONNXRUNTIME_DIR}/include"
                  "${AVATARMAP_ONNXRUNTIME_DIR}/include/onnxruntime"
            NO_DEFAULT_PATH)
  find_library(AVATARMAP_ONNXRUNTIME_LIBRARY NAMES onnxruntime
               PATHS "${AVATARMAP_ONNXRUNTIME_DIR}/lib" "${AVATARMAP_ONNXRUNTIME_DIR}/lib64"
               NO_DEFAULT_PATH)
  if(NOT AVATARMAP_ONNXRUNTIME_INCLUDE_DIR OR NOT AVATARMAP_ONNXRUNTIME_LIBRARY)
    unset(AVATARMAP_ONNXRUNTIME_INCLUDE_DIR CACHE)
    unset(AVATARMAP_ONNXRUNTIME_LIBRARY CACHE)
    message(FATAL_ERROR
      "AVATARMAP_WITH_ONNX=ON but ONNX Runtime was not found: no onnxruntime package config, "
      "and no include/onnxruntime_c_api.h + lib/libonnxruntime.so under "
      "AVATARMAP_ONNXRUNTIME_DIR=${AVATARMAP_ONNXRUNTIME_DIR}. Run scripts/fetch_onnxruntime.sh "
      "(fills .cache/avatarmap/onnxruntime), or pass -DAVATARMAP_ONNXRUNTIME_DIR=<prefix> or "
      "-Donnxruntime_DIR=<dir with onnxruntimeConfig.cmake>. See docs/models.md.")
  endif()

  add_library(onnxruntime::onnxruntime SHARED IMPORTED GLOBAL)
  set_target_properties(onnxruntime::onnxruntime PROPERTIES
    IMPORTED_LOCATION "${AVATARMAP_ONNXRUNTIME_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${AVATARMAP_ONNXRUNTIME_INCLUDE_DIR}")
  # The library's soname (libonnxruntime.so.1) is what executables record: the prefix must
  # hold that link next to the library (scripts/fetch_onnxruntime.sh makes it).
  get_filename_component(_avm_ort_libdir "${AVATARMAP_ONNXRUNTIME_LIBRARY}" DIRECTORY)
  if(EXISTS "${_avm_ort_libdir}/libonnxruntime.so.1")
    set_target_properties(onnxruntime::onnxruntime PROPERTIES IMPORTED_SONAME libonnxruntime.so.1)
  else()
    message(WARNING "ONNX Runtime: ${_avm_ort_libdir} has no libonnxruntime.so.1 link; "
                    "programs may fail to load the library")
  endif()
  message(STATUS "ONNX Runtime: ${AVATARMAP_ONNXRUNTIME_LIBRARY}")
endif()

get_target_property(_avm_ort_includes onnxruntime::onnxruntime INTERFACE_INCLUDE_DIRECTORIES)
foreach(_dir IN LISTS _avm_ort_includes)
  foreach(_sub "" "onnxruntime/")
    if(EXISTS "${_dir}/${_sub}onnxruntime_c_api.h")
      file(STRINGS "${_dir}/${_sub}onnxruntime_c_api.h" _line
           REGEX "^#define ORT_API_VERSION [0-9]+")
      string(REGEX REPLACE "^#define ORT_API_VERSION ([0-9]+).*" "\\1"
             ONNXRuntime_API_VERSION "${_line}")
    endif()
  endforeach()
endforeach()
if(ONNXRuntime_API_VERSION)
  message(STATUS "ONNX Runtime: headers ORT_API_VERSION ${ONNXRuntime_API_VERSION}")
endif()
