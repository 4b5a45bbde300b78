# The OpenCL backend. Included by the top-level CMakeLists.txt; also run as a
# script (cmake -P) at build time to embed kernels/fmm_rows.cl with its
# #include "march/march.h" line replaced by src/march/march.h (and that
# file's #include "local_update.h" by src/march/local_update.h), so the
# embedded program is self-contained.

if(CMAKE_SCRIPT_MODE_FILE)
  # -DKERNEL=... -DSRC_DIR=<src/> -DOUT=...
  file(READ "${SRC_DIR}/march/local_update.h" lu)
  file(READ "${SRC_DIR}/march/march.h" march)
  file(READ "${KERNEL}" text)
  string(REPLACE "#include \"local_update.h\"" "${lu}" march "${march}")
  string(REPLACE "#include \"march/march.h\"" "${march}" text "${text}")
  if(text MATCHES "#include \"")
    message(FATAL_ERROR "${KERNEL}: an #include was left unexpanded")
  endif()
  file(WRITE "${OUT}.txt" "${text}")
  file(READ "${OUT}.txt" hex HEX)
  string(LENGTH "${hex}" nhex)
  math(EXPR nbytes "${nhex} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," hex "${hex}")
  string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n" hex "${hex}")
  file(WRITE "${OUT}.tmp"
    "/* Generated from kernels/fmm_rows.cl by cmake/opencl.cmake. Do not edit. */\n"
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
  COMMAND ${CMAKE_COMMAND} -DKERNEL=${CMAKE_CURRENT_SOURCE_DIR}/kernels/fmm_rows.cl
          -DSRC_DIR=${CMAKE_CURRENT_SOURCE_DIR}/src -DOUT=${MESHFMM_KERNEL_C}
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/opencl.cmake
  DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/kernels/fmm_rows.cl
          ${CMAKE_CURRENT_SOURCE_DIR}/src/march/local_update.h
          ${CMAKE_CURRENT_SOURCE_DIR}/src/march/march.h
          ${CMAKE_CURRENT_SOURCE_DIR}/cmake/opencl.cmake
  COMMENT "Embedding kernels/fmm_rows.cl"
  VERBATIM)
target_sources(meshfmm_objects PRIVATE ${MESHFMM_KERNEL_C})
target_compile_definitions(meshfmm_objects PRIVATE MESHFMM_HAVE_OPENCL CL_TARGET_OPENCL_VERSION=120)
target_include_directories(meshfmm_objects SYSTEM PRIVATE ${MESHFMM_OPENCL_INCLUDE_DIR})
