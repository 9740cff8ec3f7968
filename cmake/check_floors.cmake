# The house's floors (docs/house.md), checked at build time: each room includes only the rooms
# below it; the rooms that must work with every env family (learn/, teach/) see envs only
# through the Env interface (envs/env.h, envs/info.h, envs/action_check.h); eval/ sees the Env
# interface, the Task interface and the BabyBench env it evaluates, never a concrete task (the
# tasks own their panels) and of the senses only the renderer; and no room but envs/ (and the
# apps/ and python/ rooms, which are not checked) dynamic_casts to an envs:: type.
# Fails (FATAL_ERROR, so the build fails) naming every violation.
# Run as: cmake -DSRC=<source dir> [-DSTAMP=<file to touch>] -P check_floors.cmake
cmake_minimum_required(VERSION 3.22)

# What each room may include besides itself (apps/ and python/ may include everything).
set(floor_core "")
set(floor_model core)
set(floor_sim core)
set(floor_scene core model sim)
set(floor_senses core model sim)
set(floor_envs core model scene senses sim tma sami)
# The env families below envs/ (their own rooms).
set(floor_tma core)
set(floor_sami core sim senses)
set(floor_eval core model envs)
set(floor_learn core envs)
set(floor_teach core envs)
set(floor_dist core)
set(floor_train core senses envs eval learn teach tma sami dist)
# The only env headers learn/, teach/ and eval/ may include.
set(interface_only learn teach eval)
set(interface_headers "envs/env.h" "envs/info.h" "envs/action_check.h")
string(JOIN ", " interface_text ${interface_headers})

get_filename_component(SRC "${SRC}" ABSOLUTE)
set(violations "")
foreach(room core model sim scene senses tma sami envs eval learn teach dist train)
  file(GLOB_RECURSE files "${SRC}/src/${room}/*.h" "${SRC}/src/${room}/*.cc")
  string(JOIN ", " allowed ${floor_${room}})
  foreach(file ${files})
    file(RELATIVE_PATH rel "${SRC}" "${file}")
    file(STRINGS "${file}" includes REGEX "^#include \"[a-z_]+/")
    foreach(line ${includes})
      string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" header "${line}")
      string(REGEX REPLACE "/.*" "" target "${header}")
      if(target STREQUAL room)
        continue()
      endif()
      if(NOT target IN_LIST floor_${room})
        list(APPEND violations "${rel} includes ${header} (${room}/ may include: ${allowed})")
      elseif(target STREQUAL "envs" AND room IN_LIST interface_only
             AND NOT header IN_LIST interface_headers)
        list(APPEND violations "${rel} includes ${header} (only the Env interface: ${interface_text})")
      endif()
    endforeach()
    if(NOT room STREQUAL "envs")
      file(STRINGS "${file}" casts REGEX "dynamic_cast<[^>]*envs::")
      foreach(line ${casts})
        string(REPLACE ";" "" line "${line}")
        string(STRIP "${line}" line)
        if(NOT line STREQUAL "")
          list(APPEND violations "${rel}: ${line}")
        endif()
      endforeach()
    endif()
  endforeach()
endforeach()

if(violations)
  list(JOIN violations "\n  " text)
  message(FATAL_ERROR "floor check failed (docs/house.md):\n  ${text}")
endif()
if(STAMP)
  file(TOUCH "${STAMP}")
endif()
