# libpointmech.so: every layer's objects (the archives' own, compiled once)
# and the interface of include/pointmech.h (src/api).  The pointmech
# program links it; the tests link the archives.  Only pointmech.h is the
# stable interface: the program also calls the layers' functions, which the
# library exports for it, so the SONAME changes with every minor version
# before 1.0 (libpointmech.so.0.1).
include(GNUInstallDirs)
file(GLOB PM_API_SRC CONFIGURE_DEPENDS src/api/*.c)
set(PM_LAYERS pm_app pm_fpm pm_fpm_ranks pm_fpm_core pm_mpm pm_mpm_ranks
  pm_mpm_core pm_geometry pm_common)
set(pm_layer_objects)
foreach(layer ${PM_LAYERS})
  list(APPEND pm_layer_objects $<TARGET_OBJECTS:${layer}>)
endforeach()
add_library(pointmech_lib SHARED ${PM_API_SRC} ${pm_layer_objects})
set_target_properties(pointmech_lib PROPERTIES OUTPUT_NAME pointmech
  EXPORT_NAME pointmech VERSION ${PROJECT_VERSION}
  SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
target_include_directories(pointmech_lib
  PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
         $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
  PRIVATE src/api)
# The archives' usage requirements (headers, definitions, the libraries
# they call); their objects are in the library already, so the linker
# takes nothing more from them.  Calls inside the library bind to it.
target_link_libraries(pointmech_lib PRIVATE pm_app)
target_link_options(pointmech_lib PRIVATE -Wl,-Bsymbolic-functions)
# --no-undefined: a function of a library opened on first use (gmsh) that
# a call site reaches without its table stays undefined, and fails here.
# Not with the sanitizers, whose runtime the program brings (clang's).
if(NOT PM_SANITIZE AND NOT PM_FUZZ)
  target_link_options(pointmech_lib PRIVATE -Wl,--no-undefined)
endif()
foreach(layer ${PM_LAYERS})
  add_dependencies(pointmech_lib ${layer})
endforeach()

# The program: the layers' headers, the library's code.
target_include_directories(pointmech PRIVATE
  $<TARGET_PROPERTY:pm_app,INTERFACE_INCLUDE_DIRECTORIES>)
target_compile_definitions(pointmech PRIVATE
  $<TARGET_PROPERTY:pm_app,INTERFACE_COMPILE_DEFINITIONS>)
target_link_libraries(pointmech PRIVATE pointmech_lib MPI::MPI_C)
if(PM_OPENMP)
  target_link_libraries(pointmech PRIVATE OpenMP::OpenMP_C)
endif()

# cmake --install build --prefix P: the program, the library, pointmech.h,
# the CMake package (find_package(pointmech): pointmech::pointmech) and
# pointmech.pc.
include(CMakePackageConfigHelpers)
set_target_properties(pointmech PROPERTIES
  INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
install(TARGETS pointmech RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS pointmech_lib EXPORT pointmechTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(FILES include/pointmech.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
set(PM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/pointmech)
install(EXPORT pointmechTargets NAMESPACE pointmech::
  DESTINATION ${PM_CMAKE_DIR})
configure_package_config_file(cmake/pointmechConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/pointmechConfig.cmake
  INSTALL_DESTINATION ${PM_CMAKE_DIR})
write_basic_package_version_file(
  ${CMAKE_CURRENT_BINARY_DIR}/pointmechConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/pointmechConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/pointmechConfigVersion.cmake
  DESTINATION ${PM_CMAKE_DIR})
# The prefix from the .pc file's own place: right wherever --prefix puts it.
file(RELATIVE_PATH PM_PC_TO_PREFIX
  /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" PM_PC_TO_PREFIX "${PM_PC_TO_PREFIX}")
configure_file(cmake/pointmech.pc.in ${CMAKE_CURRENT_BINARY_DIR}/pointmech.pc
  @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/pointmech.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
