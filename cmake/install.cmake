# cmake --install BUILD --prefix DIR: the oprt command, the model's static libraries with their
# headers (DIR/include/oprt, the layout the code includes: "hw/engine.h"), a CMake package
# (find_package(oprt CONFIG): oprt::model, one target per layer, oprt::oprt) and oprt.pc.
# examples/platform builds against it (tests/scripts/test_platform.sh).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(OPRT_LIBRARIES oprt_base oprt_sample oprt_geom oprt_scene oprt_arch oprt_balance oprt_ref oprt_timing oprt_analytic oprt_cost oprt_trace oprt_hw)
foreach(lib IN LISTS OPRT_LIBRARIES)
  string(REPLACE "oprt_" "" name ${lib})
  set_target_properties(${lib} PROPERTIES EXPORT_NAME ${name})
endforeach()

# What the headers need of a consumer's compiler, as this build compiles them (the project's
# add_compile_options apply only inside the tree): C++17 exactly (Debian's libsystemc), no
# contraction of a multiply and an add (the kernels' bits: CMakeLists.txt), and the
# instruction set the SIMD kernels in the headers were built for (geom/simd.h).
set(OPRT_EXPORTED_OPTIONS -ffp-contract=off -fno-fast-math)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  list(APPEND OPRT_EXPORTED_OPTIONS -fno-tree-slp-vectorize)
endif()
if(OPRT_NATIVE)
  list(APPEND OPRT_EXPORTED_OPTIONS -march=native)
endif()
set(OPRT_EXPORTED_LINK_OPTIONS)
if(OPRT_SANITIZE)  # instrumented libraries need the sanitizers' runtimes
  list(APPEND OPRT_EXPORTED_OPTIONS -fsanitize=address,undefined -fno-omit-frame-pointer)
  list(APPEND OPRT_EXPORTED_LINK_OPTIONS -fsanitize=address,undefined)
endif()
foreach(lib oprt_base oprt_geom)  # the two bottom layers: every other library links one of them
  target_compile_features(${lib} PUBLIC cxx_std_17)
  target_compile_options(${lib} INTERFACE "$<INSTALL_INTERFACE:${OPRT_EXPORTED_OPTIONS}>")
  target_compile_definitions(${lib} INTERFACE "$<INSTALL_INTERFACE:OPRT_FP_CONTRACT_OFF=1>")
  target_link_options(${lib} INTERFACE "$<INSTALL_INTERFACE:${OPRT_EXPORTED_LINK_OPTIONS}>")
endforeach()

install(TARGETS ${OPRT_LIBRARIES} oprt_model fstapi EXPORT oprtTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS oprt EXPORT oprtTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/model/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/oprt
        FILES_MATCHING PATTERN "*.h")
install(EXPORT oprtTargets NAMESPACE oprt:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oprt)

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/oprtConfig.cmake.in ${PROJECT_BINARY_DIR}/oprtConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oprt)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/oprtConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/oprtConfig.cmake ${PROJECT_BINARY_DIR}/oprtConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oprt)

# pkg-config: the same flags; relocatable (${pcfiledir}), as the CMake package is.
list(JOIN OPRT_EXPORTED_OPTIONS " " OPRT_PC_CFLAGS)
set(OPRT_PC_CFLAGS "-std=c++17 ${OPRT_PC_CFLAGS} -DOPRT_FP_CONTRACT_OFF=1")
list(JOIN OPRT_EXPORTED_LINK_OPTIONS " " OPRT_PC_LIBS)
configure_file(${CMAKE_CURRENT_LIST_DIR}/oprt.pc.in ${PROJECT_BINARY_DIR}/oprt.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/oprt.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# --- The Python package (issue 40) --------------------------------------------------------------
# python/oprt into DIR/lib/python3/dist-packages/oprt (Debian's layout, whatever the library
# folder): `PYTHONPATH=DIR/lib/python3/dist-packages python3 -c 'import oprt'`, or a .pth file
# naming that folder in an environment's site-packages. Installed so, the package runs
# DIR/bin/oprt by default (oprt.paths.installed_oprt); tests/scripts/test_platform.sh imports it.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/python/oprt DESTINATION lib/python3/dist-packages
        FILES_MATCHING PATTERN "*.py" PATTERN "__pycache__" EXCLUDE)
