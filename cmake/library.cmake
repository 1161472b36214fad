# libcadmorph: ONE library (shared and static) from the objects of every library module.
#
# The modules stay separate static libraries (cm_core, cm_rbf, ...): each links only what its
# row of DESIGN.md allows, so a wrong-way dependency fails to link, and tests link just the
# module they test. Their objects are compiled once, position-independent and with hidden
# symbols, and both libcadmorph variants are made from them: only functions marked CM_API
# (cadmorph/export.h) are exported from libcadmorph.so.
#
# A new library module adds its target to CM_LIBRARY_MODULES; its private dependencies (the
# non-module entries of its target_link_libraries) follow it into libcadmorph by themselves.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(CM_LIBRARY_MODULES cm_core cm_platform cm_rbf cm_mesh cm_deform cm_mls cm_cad cm_surface cm_volume
  cm_meshgen cm_morph)
if(TARGET cm_study)
  list(APPEND CM_LIBRARY_MODULES cm_study)
endif()

set(CM_LIBRARY_OBJECTS)
set(CM_LIBRARY_DEPS)
foreach(m IN LISTS CM_LIBRARY_MODULES)
  set_target_properties(${m} PROPERTIES
    POSITION_INDEPENDENT_CODE ON
    C_VISIBILITY_PRESET hidden
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  target_compile_definitions(${m} PRIVATE CM_BUILDING_LIBRARY)
  list(APPEND CM_LIBRARY_OBJECTS $<TARGET_OBJECTS:${m}>)
  get_target_property(deps ${m} LINK_LIBRARIES)
  foreach(d IN LISTS deps)
    if(NOT d IN_LIST CM_LIBRARY_MODULES AND NOT d MATCHES "^cm_(warnings|posix)$")
      list(APPEND CM_LIBRARY_DEPS ${d})
    endif()
  endforeach()
endforeach()
list(REMOVE_DUPLICATES CM_LIBRARY_DEPS)

set(CM_LIBRARY_INCLUDES
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
  $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/include>
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)

# 0.x: every minor version may change the ABI, so it is part of the soname.
add_library(cadmorph_lib SHARED ${CM_LIBRARY_OBJECTS})
set_target_properties(cadmorph_lib PROPERTIES
  OUTPUT_NAME cadmorph EXPORT_NAME cadmorph LINKER_LANGUAGE CXX
  VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
target_include_directories(cadmorph_lib PUBLIC ${CM_LIBRARY_INCLUDES})
target_link_libraries(cadmorph_lib PRIVATE ${CM_LIBRARY_DEPS})
# every symbol the objects need is resolved now, not in a user's program
target_link_options(cadmorph_lib PRIVATE LINKER:--no-undefined
  LINKER:--version-script=${PROJECT_SOURCE_DIR}/cmake/libcadmorph.map)
set_property(TARGET cadmorph_lib APPEND PROPERTY LINK_DEPENDS ${PROJECT_SOURCE_DIR}/cmake/libcadmorph.map)

add_library(cadmorph_static STATIC ${CM_LIBRARY_OBJECTS})
set_target_properties(cadmorph_static PROPERTIES
  OUTPUT_NAME cadmorph EXPORT_NAME cadmorph_static LINKER_LANGUAGE CXX)
target_include_directories(cadmorph_static PUBLIC ${CM_LIBRARY_INCLUDES})
# In the build tree the dependencies follow the static library as targets; the installed
# package names them again (cadmorphConfig.cmake, cadmorph.pc) from the lists below.
foreach(d IN LISTS CM_LIBRARY_DEPS)
  target_link_libraries(cadmorph_static PRIVATE $<BUILD_INTERFACE:${d}>)
endforeach()
foreach(t cadmorph_lib cadmorph_static)
  add_dependencies(${t} ${CM_LIBRARY_MODULES})
endforeach()
add_library(cadmorph::cadmorph ALIAS cadmorph_lib)
add_library(cadmorph::cadmorph_static ALIAS cadmorph_static)

# ---- the private dependencies as files, for static linking outside this build ----
# OpenMP and zlib are found again by find_dependency (they have CMake modules); the others
# (OpenCASCADE toolkits, FLANN, LAPACKE/OpenBLAS, TetGen) are the files found here.
function(cm_dependency_files out)
  set(files)
  foreach(d IN LISTS ARGN)
    if(d MATCHES "^(OpenMP|ZLIB)::")
      continue()
    elseif(TARGET ${d})
      get_target_property(type ${d} TYPE)
      if(type STREQUAL "INTERFACE_LIBRARY")
        get_target_property(sub ${d} INTERFACE_LINK_LIBRARIES)
        if(sub)
          cm_dependency_files(subfiles ${sub})
          list(APPEND files ${subfiles})
        endif()
      else()
        message(FATAL_ERROR "cmake/library.cmake: name the file of dependency ${d} for static linking")
      endif()
    elseif(d MATCHES "^/")
      list(APPEND files ${d})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES files)
  set(${out} ${files} PARENT_SCOPE)
endfunction()
cm_dependency_files(CM_STATIC_FILES ${CM_LIBRARY_DEPS})

# pkg-config: -L<dir> -l<name> for each file; zlib by its own .pc
set(CM_PC_LIBS_PRIVATE)
set(CM_PC_DIRS)
foreach(f IN LISTS CM_STATIC_FILES)
  get_filename_component(dir ${f} DIRECTORY)
  get_filename_component(name ${f} NAME_WE)
  string(REGEX REPLACE "^lib" "" name ${name})
  if(NOT dir IN_LIST CM_PC_DIRS)
    list(APPEND CM_PC_DIRS ${dir})
    string(APPEND CM_PC_LIBS_PRIVATE " -L${dir}")
  endif()
  string(APPEND CM_PC_LIBS_PRIVATE " -l${name}")
endforeach()
string(APPEND CM_PC_LIBS_PRIVATE " ${OpenMP_C_FLAGS} -lstdc++")
string(REPLACE ";" " " CM_CONFIG_STATIC_FILES "${CM_STATIC_FILES}")

# from <libdir>/pkgconfig up to the prefix, so that the file holds for any install prefix
file(RELATIVE_PATH CM_PC_UP /p/${CMAKE_INSTALL_LIBDIR}/pkgconfig /p)
configure_file(${PROJECT_SOURCE_DIR}/cmake/cadmorph.pc.in ${PROJECT_BINARY_DIR}/cadmorph.pc @ONLY)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/cadmorphConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cadmorphConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/cadmorph)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cadmorphConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)

# ---- install ----
install(TARGETS cadmorph_lib cadmorph_static EXPORT cadmorphTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/cadmorph DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/include/cadmorph/version.h
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/cadmorph)
install(EXPORT cadmorphTargets NAMESPACE cadmorph::
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/cadmorph)
install(FILES ${PROJECT_BINARY_DIR}/cadmorphConfig.cmake
  ${PROJECT_BINARY_DIR}/cadmorphConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/cadmorph)
install(FILES ${PROJECT_BINARY_DIR}/cadmorph.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
# the design, the style and the references that the installed headers cite
install(FILES ${PROJECT_SOURCE_DIR}/docs/DESIGN.md ${PROJECT_SOURCE_DIR}/docs/STYLE.md
  ${PROJECT_SOURCE_DIR}/docs/references.md ${PROJECT_SOURCE_DIR}/docs/ffd.md
  DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)
