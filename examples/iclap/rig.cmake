# Rig support of the `iclap` program (`devices`, `record`): hidapi for HID
# peripherals, OpenHaptics for the Omni arm when installed. Included by
# examples/CMakeLists.txt. The iclap library itself never needs either.

# hidapi (Debian: libhidapi-dev), hidraw backend preferred, libusb otherwise.
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND AND NOT TARGET PkgConfig::ICLAP_HIDAPI)
  pkg_check_modules(ICLAP_HIDAPI QUIET IMPORTED_TARGET GLOBAL hidapi-hidraw)
  if(NOT ICLAP_HIDAPI_FOUND)
    pkg_check_modules(ICLAP_HIDAPI QUIET IMPORTED_TARGET GLOBAL hidapi-libusb)
  endif()
endif()
if(TARGET PkgConfig::ICLAP_HIDAPI)
  target_link_libraries(iclap_cli PRIVATE PkgConfig::ICLAP_HIDAPI)
  target_compile_definitions(iclap_cli PRIVATE ICLAP_HAVE_HIDAPI)
  message(STATUS "iclap: hidapi ${ICLAP_HIDAPI_VERSION} found: `iclap devices` lists HID devices")
else()
  message(STATUS "iclap: hidapi not found (pkg-config hidapi-hidraw): `iclap devices` lists serial ports only")
endif()

# OpenHaptics (HD API) for `--pose omni`: not packaged by Debian; found when
# installed (OH_SDK_BASE, /opt/OpenHaptics). Untested code path.
option(ICLAP_WITH_OPENHAPTICS "Read the Omni arm through OpenHaptics when it is installed" ON)
if(ICLAP_WITH_OPENHAPTICS)
  find_path(ICLAP_OPENHAPTICS_INCLUDE_DIR HD/hd.h
            HINTS ENV OH_SDK_BASE PATH_SUFFIXES include
            PATHS /opt/OpenHaptics/Developer /usr/local /usr)
  find_library(ICLAP_OPENHAPTICS_HD_LIBRARY NAMES HD
               HINTS ENV OH_SDK_BASE PATH_SUFFIXES lib lib64
               PATHS /opt/OpenHaptics/Developer /usr/local /usr)
  mark_as_advanced(ICLAP_OPENHAPTICS_INCLUDE_DIR ICLAP_OPENHAPTICS_HD_LIBRARY)
  if(ICLAP_OPENHAPTICS_INCLUDE_DIR AND ICLAP_OPENHAPTICS_HD_LIBRARY)
    target_include_directories(iclap_cli SYSTEM PRIVATE ${ICLAP_OPENHAPTICS_INCLUDE_DIR})
    target_link_libraries(iclap_cli PRIVATE ${ICLAP_OPENHAPTICS_HD_LIBRARY})
    target_compile_definitions(iclap_cli PRIVATE ICLAP_HAVE_OPENHAPTICS)
    message(STATUS "iclap: OpenHaptics found: `iclap record --pose omni` enabled (untested code path)")
  else()
    message(STATUS "iclap: OpenHaptics not found (HD/hd.h): `--pose omni` disabled")
  endif()
endif()
