# SPDX-License-Identifier: MIT
# Embeds GLSL sources in a C header at build time: for every NAME.STAGE.glsl of FILES a
# `static const char sw_glsl_NAME_STAGE[]` holding its bytes and a terminating NUL.
# Usage: cmake -DOUT=header.h -DFILES=a.glsl,b.glsl -P embed_glsl.cmake (gpu/CMakeLists.txt lists
# them)
string(REPLACE "," ";" files "${FILES}")
list(SORT files)
string(REPEAT "0x[0-9a-f][0-9a-f]," 16 row) # CMake's regular expressions have no {n}
set(text "/* Generated from gpu/glsl/NAME.glsl by gpu/glsl/embed_glsl.cmake: do not edit. */\n")
foreach(f ${files})
  get_filename_component(name ${f} NAME)
  string(REGEX REPLACE "\\.glsl$" "" name ${name})
  string(REGEX REPLACE "[^A-Za-z0-9]" "_" name ${name})
  file(READ ${f} hex HEX)
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  string(REGEX REPLACE "(${row})" "\\1\n    " bytes "${bytes}")
  string(APPEND text "static const char sw_glsl_${name}[] = {\n    ${bytes}0x00};\n")
endforeach()
file(WRITE ${OUT} "${text}")
