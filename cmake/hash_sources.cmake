# Writes a header defining SB_SCENES_SOURCE_HASH, the SHA-256 of the scene generator sources, so
# that cached built-in scenes are regenerated whenever a generator changes.
# Usage: cmake -DOUT=<header> -DSOURCES=<a|b|c> -P hash_sources.cmake
string(REPLACE "|" ";" SOURCES "${SOURCES}")
set(all "")
foreach(f ${SOURCES})
  file(SHA256 ${f} h)
  string(APPEND all "${h}")
endforeach()
string(SHA256 digest "${all}")
string(SUBSTRING ${digest} 0 16 digest)
set(text "// Generated: hash of the scene generator sources.\n#pragma once\n#define SB_SCENES_SOURCE_HASH \"${digest}\"\n")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
  if(old STREQUAL text)
    return()
  endif()
endif()
file(WRITE ${OUT} "${text}")
