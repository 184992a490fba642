# What a lab machine installs (GNUInstallDirs): the services and tools, the
# deployment data (scenes, DDS profiles, lab examples, systemd units) and the
# meshes the scenes name, a package configuration for find_package(fahr),
# and a Debian package (CPack DEB) that names its runtime dependencies.
include(CMakePackageConfigHelpers)

set(FAHR_INSTALLED_PROGRAMS
  fahr_device_gateway fahr_fem_service fahr_haptic_service fahr_logger fahr_lockstep_clock
  fahr_run_summary fahr_lab fahr_dds_check fahr_scene_check fahr_replay)
foreach(program IN LISTS FAHR_INSTALLED_PROGRAMS)
  if(TARGET ${program})
    install(TARGETS ${program} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()

# The scenes name their meshes as ../../meshes/...: the same layout under
# share/fahr keeps those paths valid.
set(FAHR_DATA_DIR ${CMAKE_INSTALL_DATADIR}/fahr)
install(DIRECTORY deployment/scenes deployment/dds deployment/labs
  DESTINATION ${FAHR_DATA_DIR}/deployment)
install(DIRECTORY meshes/ DESTINATION ${FAHR_DATA_DIR}/meshes
  PATTERN "*.png" EXCLUDE)
# systemd template units, written at install time so that ExecStart names
# the programs where this install puts them (cmake --install --prefix, or
# CPack's /usr); the station's target; the socket-buffer limits.
file(GLOB FAHR_UNIT_TEMPLATES ${CMAKE_CURRENT_SOURCE_DIR}/deployment/systemd/*.service.in)
set(FAHR_SYSTEMD_UNIT_DIR lib/systemd/system CACHE STRING
  "where the systemd units go, relative to the prefix")
install(CODE "
  foreach(template ${FAHR_UNIT_TEMPLATES})
    get_filename_component(unit \${template} NAME_WLE)
    set(CMAKE_INSTALL_FULL_BINDIR \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
    set(destination \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${FAHR_SYSTEMD_UNIT_DIR}\")
    message(STATUS \"Installing: \${destination}/\${unit}\")
    configure_file(\${template} \${destination}/\${unit} @ONLY)
  endforeach()")
install(FILES deployment/systemd/fahr-station@.target DESTINATION ${FAHR_SYSTEMD_UNIT_DIR})
install(FILES deployment/systemd/60-fahr.conf DESTINATION lib/sysctl.d)
install(FILES deployment/compose.yaml deployment/Dockerfile DESTINATION ${FAHR_DATA_DIR}/deployment)

configure_package_config_file(cmake/fahrConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/fahrConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/fahr
  PATH_VARS FAHR_DATA_DIR)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/fahrConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/fahrConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/fahrConfigVersion.cmake cmake/FindSuiteSparse.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/fahr)

set(CPACK_PACKAGE_NAME fahr)
set(CPACK_PACKAGE_VENDOR "fahr")
set(CPACK_PACKAGE_CONTACT "fahr maintainers <fahr@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
  "Force-aware haptic rendering over DDS: services, lab launcher, scenes and meshes")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# The shared libraries the programs link (ldd of the installed programs,
# Debian 12 package names), and the lab tools fahr_lab starts.
set(CPACK_DEBIAN_PACKAGE_DEPENDS
  "libfastrtps2.9, libfastcdr1, libddsc0debian (>= 0.10), libyaml-cpp0.7, libcholmod3, libblas3 | libblas.so.3, liblapack3 | liblapack.so.3, libassimp5, libbullet3.24, liblz4-1, libzstd1, zlib1g, libstdc++6, fastdds-tools, nftables")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libopenblas0-pthread, chrony")
include(CPack)
