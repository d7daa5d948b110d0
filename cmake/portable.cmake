# The portable libdwivedi.so.1 that the Blender packages carry (issue 16): the same sources, the
# same SONAME and version script as the `dwivedi` target, linked against static, position-
# independent builds of every dependency (scripts/build-portable-deps.sh makes the prefix), so
# that its ELF NEEDED entries are libc, libm, libstdc++ and libgcc_s only and it exports dwv_*
# only. Every dependency symbol is local to it: the host's Embree, OpenEXR, OpenColorIO, TBB,
# libpng, zlib, yaml-cpp (any version, already loaded) can neither interpose it nor be interposed.
#
#   prefix=$(bash scripts/build-portable-deps.sh | tail -n 1)
#   cmake -S . -B build -DDWV_PORTABLE_DEPS="$prefix"     # adds the target dwivedi_portable:
#   cmake --build build --target dwivedi_portable          # build/portable/libdwivedi.so.1
#
# Included from CMakeLists.txt after the library's object targets exist. It takes them from
# DWV_LIBRARY_OBJECT_TARGETS (one OBJECT library per module), or dwivedi_objects when that list is
# empty, and compiles each one's sources again into a twin OBJECT library (<target>_portable) with
# the same properties, whose dependency headers are the prefix's instead of the system's: the
# prefix holds OpenColorIO 2.1.3 where the system has 2.1.2, so the headers are not all identical
# and objects compiled against the system's cannot simply be reused (the other dependencies'
# headers are the same versions; scripts/build-portable-deps.sh's prefix has VERSIONS).
#
# Sets DWV_PACKAGED_LIBRARY_TARGET to dwivedi_portable (the library the add-on zip should carry).

set(DWV_PORTABLE_DEPS "" CACHE PATH
  "Prefix of the static dependencies (scripts/build-portable-deps.sh); when set, builds build/portable/libdwivedi.so.1")
option(DWV_PORTABLE_STATIC_CXX "Also link libstdc++ and libgcc statically into the portable library (hidden)" OFF)
if(NOT DWV_PORTABLE_DEPS)
  return()
endif()
if(DWV_SANITIZE OR DWV_BUILD_FUZZERS)
  message(FATAL_ERROR "DWV_PORTABLE_DEPS cannot be combined with DWV_SANITIZE or DWV_BUILD_FUZZERS "
                      "(the sanitizer runtimes are shared libraries the packaged library must not need)")
endif()
if(NOT EXISTS "${DWV_PORTABLE_DEPS}/.complete")
  message(FATAL_ERROR "DWV_PORTABLE_DEPS=${DWV_PORTABLE_DEPS} is not a complete prefix made by "
                      "scripts/build-portable-deps.sh (no .complete file); run the script and pass the path it prints")
endif()

set(dwv_pd ${DWV_PORTABLE_DEPS})
# Every static library the link needs, in the prefix's lib/ (an archive missing is an error here,
# not an undefined symbol later). Embree's static build is several archives.
set(dwv_portable_archive_names
  libOpenColorIO.a libyaml-cpp.a libpystring.a libexpat.a libImath-3_1.a libOpenEXRCore-3_1.a
  libassimp.a libminizip.a libcjson.a libpng16.a libz.a
  libembree3.a libsimd.a liblexers.a libsys.a libmath.a libtasking.a)
set(dwv_portable_archives)
foreach(name IN LISTS dwv_portable_archive_names)
  if(NOT EXISTS "${dwv_pd}/lib/${name}")
    message(FATAL_ERROR "DWV_PORTABLE_DEPS: ${dwv_pd}/lib/${name} is missing (rebuild the prefix with scripts/build-portable-deps.sh)")
  endif()
  list(APPEND dwv_portable_archives "${dwv_pd}/lib/${name}")
endforeach()
# Embree's kernels of each ISA it was built for (libembree_avx2.a...), and any helper archives
# OpenColorIO's static build leaves beside it.
file(GLOB dwv_portable_extra_archives "${dwv_pd}/lib/libembree_*.a" "${dwv_pd}/lib/libOpenColorIO*.a"
     "${dwv_pd}/lib/libsampleicc*.a" "${dwv_pd}/lib/libutils*.a")
list(REMOVE_ITEM dwv_portable_extra_archives ${dwv_portable_archives})
list(APPEND dwv_portable_archives ${dwv_portable_extra_archives})
set(dwv_portable_includes ${dwv_pd}/include ${dwv_pd}/include/OpenEXR ${dwv_pd}/include/cjson)
foreach(dir IN LISTS dwv_portable_includes)
  if(NOT IS_DIRECTORY "${dir}")
    message(FATAL_ERROR "DWV_PORTABLE_DEPS: ${dir} is missing")
  endif()
endforeach()

set(dwv_portable_sources_of ${DWV_LIBRARY_OBJECT_TARGETS})
if(NOT dwv_portable_sources_of)
  set(dwv_portable_sources_of dwivedi_objects)
endif()

# Properties copied from each object target to its twin (usage requirements of the targets it
# links come through the links themselves, below).
set(dwv_portable_copied_properties INCLUDE_DIRECTORIES COMPILE_DEFINITIONS COMPILE_OPTIONS COMPILE_FEATURES
  C_STANDARD C_STANDARD_REQUIRED C_EXTENSIONS CXX_STANDARD CXX_STANDARD_REQUIRED CXX_EXTENSIONS
  POSITION_INDEPENDENT_CODE C_VISIBILITY_PRESET CXX_VISIBILITY_PRESET VISIBILITY_INLINES_HIDDEN)
set(dwv_portable_objects)
foreach(target IN LISTS dwv_portable_sources_of)
  if(NOT TARGET ${target})
    message(FATAL_ERROR "cmake/portable.cmake: ${target} (from DWV_LIBRARY_OBJECT_TARGETS) is not a target")
  endif()
  get_target_property(sources ${target} SOURCES)
  get_target_property(source_dir ${target} SOURCE_DIR)
  set(absolute_sources)
  foreach(source IN LISTS sources)
    if(source MATCHES "^\\$<" OR IS_ABSOLUTE "${source}")
      list(APPEND absolute_sources "${source}")
    else()
      list(APPEND absolute_sources "${source_dir}/${source}")
    endif()
  endforeach()
  set(twin ${target}_portable)
  add_library(${twin} OBJECT ${absolute_sources})
  foreach(property IN LISTS dwv_portable_copied_properties)
    get_target_property(value ${target} ${property})
    if(NOT value STREQUAL "value-NOTFOUND")
      set_property(TARGET ${twin} PROPERTY ${property} "${value}")
    endif()
  endforeach()
  set_target_properties(${twin} PROPERTIES POSITION_INDEPENDENT_CODE ON C_VISIBILITY_PRESET hidden
    CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  # The twin links what its original links, except imported (dependency) targets: the project's
  # own targets bring their include roots, Threads its flags; the dependencies' headers come from
  # the prefix, first on the include path.
  get_target_property(links ${target} LINK_LIBRARIES)
  if(links)
    foreach(link IN LISTS links)
      if(TARGET ${link})
        get_target_property(imported ${link} IMPORTED)
        if(imported AND NOT link STREQUAL "Threads::Threads")
          continue()
        endif()
      endif()
      target_link_libraries(${twin} PRIVATE ${link})
    endforeach()
  endif()
  target_include_directories(${twin} SYSTEM BEFORE PRIVATE ${dwv_portable_includes})
  list(APPEND dwv_portable_objects $<TARGET_OBJECTS:${twin}>)
endforeach()

add_library(dwivedi_portable SHARED ${dwv_portable_objects})
# The archives as one group (their order then does not matter); --exclude-libs,ALL makes every
# symbol they define local, and the version script leaves dwv_* the only global symbols.
# -Bsymbolic binds the library's own dwv_* references to itself. --gc-sections drops the code the
# library never reaches (the dependencies were built with a section per function).
target_link_libraries(dwivedi_portable PRIVATE Threads::Threads
  "-Wl,--start-group" ${dwv_portable_archives} "-Wl,--end-group" m)
target_link_options(dwivedi_portable PRIVATE
  "LINKER:--version-script=${PROJECT_SOURCE_DIR}/src/dwivedi.map"
  "LINKER:--exclude-libs,ALL" "LINKER:-Bsymbolic" "LINKER:--no-undefined" "LINKER:--gc-sections"
  "LINKER:--as-needed" "LINKER:-z,relro" "LINKER:-z,now" "LINKER:-z,noexecstack")
if(DWV_PORTABLE_STATIC_CXX)
  target_link_options(dwivedi_portable PRIVATE -static-libstdc++ -static-libgcc)
endif()
set_target_properties(dwivedi_portable PROPERTIES
  OUTPUT_NAME dwivedi
  LIBRARY_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/portable
  VERSION ${PROJECT_VERSION}
  SOVERSION ${DWV_HEADER_ABI_VERSION}
  LINKER_LANGUAGE CXX
  LINK_DEPENDS ${PROJECT_SOURCE_DIR}/src/dwivedi.map)
set(DWV_PACKAGED_LIBRARY_TARGET dwivedi_portable)
message(STATUS "Portable library: ${PROJECT_BINARY_DIR}/portable/libdwivedi.so.${DWV_HEADER_ABI_VERSION} "
               "(static dependencies from ${dwv_pd})")
