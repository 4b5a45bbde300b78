# The OpenCL backend. Included by the top-level CMakeLists.txt; also run as a
# script (cmake -P) at build time to embed the program: kernels/fmm_rows.cl
# (the march) and kernels/windows_rows.cl (the window method), with every
# #include "..." line replaced by that header from src/ (src/march/ or
# src/exact/ for a header named without its folder), so the embedded
# program is self-contained. Headers included twice keep their guards.

if(CMAKE_SCRIPT_MODE_FILE)
  # -DKERNEL_DIR=<kernels/> -DSRC_DIR=<src/> -DOUT=...
  set(KERNELS "${KERNEL_DIR}/fmm_rows.cl" "${KERNEL_DIR}/windows_rows.cl")
  set(text "")
  foreach(k IN LISTS KERNELS)
    file(READ "${k}" part)
    string(APPEND text "${part}\n")
  endforeach()
  set(guard 0)
  while(text MATCHES "#include \"([^\"]+)\"")
    set(inc "${CMAKE_MATCH_1}")
    set(found "")
    foreach(dir "${SRC_DIR}" "${SRC_DIR}/march" "${SRC_DIR}/exact")
      if(NOT found AND EXISTS "${dir}/${inc}")
        set(found "${dir}/${inc}")
      endif()
    endforeach()
    if(NOT found)
      message(FATAL_ERROR "${KERNELS}: #include \"${inc}\" not found under ${SRC_DIR}")
    endif()
    file(READ "${found}" body)
    string(REPLACE "#include \"${inc}\"" "${body}" text "${text}")
    math(EXPR guard "${guard} + 1")
    if(guard GREATER 50)
      message(FATAL_ERROR "${KERNELS}: #include lines nested too deep")
    endif()
  endwhile()
  file(WRITE "${OUT}.txt" "${text}")
  file(READ "${OUT}.txt" hex HEX)
  string(LENGTH "${hex}" nhex)
  math(EXPR nbytes "${nhex} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," hex "${hex}")
  string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n" hex "${hex}")
  file(WRITE "${OUT}.tmp"
    "/* Generated from kernels/fmm_rows.cl and kernels/windows_rows.cl by cmake/opencl.cmake. Do not edit. */\n"
    "#include <stddef.h>\n"
    "const char mfmm_kernel_fmm_rows[] = {\n${hex}0x00};\n"
    "const size_t mfmm_kernel_fmm_rows_len = ${nbytes};\n")
  file(RENAME "${OUT}.tmp" "${OUT}")
  return()
endif()

if(NOT MESHFMM_WITH_OPENCL)
  if(MESHFMM_REQUIRE_OPENCL)
    message(FATAL_ERROR "meshfmm: MESHFMM_REQUIRE_OPENCL=ON contradicts MESHFMM_WITH_OPENCL=OFF")
  endif()
  message(STATUS "meshfmm: OpenCL backend disabled (MESHFMM_WITH_OPENCL=OFF)")
  return()
endif()

# Only the headers: libmeshfmm opens the ICD loader (libOpenCL.so.1) at run
# time (src/matrix/opencl/loader.c), so it links no OpenCL library and loads on
# machines without one.
find_path(MESHFMM_OPENCL_INCLUDE_DIR CL/cl.h
  HINTS ${OpenCL_INCLUDE_DIR} ENV OpenCL_ROOT
  DOC "Folder holding CL/cl.h (the opencl-headers package)")
if(NOT MESHFMM_OPENCL_INCLUDE_DIR)
  if(MESHFMM_REQUIRE_OPENCL)
    message(FATAL_ERROR "meshfmm: MESHFMM_REQUIRE_OPENCL=ON and the OpenCL headers (CL/cl.h) "
      "were not found. They are a build dependency only (the library opens libOpenCL.so.1 "
      "at run time): install them (Debian: opencl-headers; or a copy of "
      "github.com/KhronosGroup/OpenCL-Headers) and point OpenCL_ROOT or OpenCL_INCLUDE_DIR "
      "at their folder, or configure with MESHFMM_REQUIRE_OPENCL=OFF for a build without "
      "the OpenCL backend.")
  endif()
  message(STATUS "meshfmm: OpenCL headers (CL/cl.h) not found; the opencl backend will report MFMM_ERR_NO_OPENCL")
  return()
endif()
message(STATUS "meshfmm: OpenCL backend on (headers in ${MESHFMM_OPENCL_INCLUDE_DIR}; libOpenCL.so.1 loaded at run time)")

set(MESHFMM_KERNEL_C ${CMAKE_CURRENT_BINARY_DIR}/generated/fmm_rows_cl.c)
add_custom_command(OUTPUT ${MESHFMM_KERNEL_C}
  COMMAND ${CMAKE_COMMAND}
          -DKERNEL_DIR=${CMAKE_CURRENT_SOURCE_DIR}/kernels
          -DSRC_DIR=${CMAKE_CURRENT_SOURCE_DIR}/src -DOUT=${MESHFMM_KERNEL_C}
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/opencl.cmake
  DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/kernels/fmm_rows.cl
          ${CMAKE_CURRENT_SOURCE_DIR}/kernels/windows_rows.cl
          ${CMAKE_CURRENT_SOURCE_DIR}/src/march/local_update.h
          ${CMAKE_CURRENT_SOURCE_DIR}/src/march/march.h
          ${CMAKE_CURRENT_SOURCE_DIR}/src/exact/face_frame.h
          ${CMAKE_CURRENT_SOURCE_DIR}/src/exact/slots_core.h
          ${CMAKE_CURRENT_SOURCE_DIR}/cmake/opencl.cmake
  COMMENT "Embedding kernels/fmm_rows.cl and kernels/windows_rows.cl"
  VERBATIM)
target_sources(meshfmm_objects PRIVATE ${MESHFMM_KERNEL_C})
target_compile_definitions(meshfmm_objects PRIVATE MESHFMM_HAVE_OPENCL CL_TARGET_OPENCL_VERSION=120)
target_include_directories(meshfmm_objects SYSTEM PRIVATE ${MESHFMM_OPENCL_INCLUDE_DIR})
