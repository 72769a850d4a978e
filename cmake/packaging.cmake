# What `cmake --install` puts where, beyond the binaries and the unit (their
# own CMakeLists), and the Debian package CPack builds from the same rules.

# Docs, with the example configs an operator starts from.
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR} FILES_MATCHING PATTERN "*.md" PATTERN "*.png")
install(FILES config/tomomapd.toml DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)
install(DIRECTORY config/local-3-agents DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)

# The config the service reads (%E/tomomap/tomomapd.toml in the unit): /etc for
# a /usr install such as the .deb, PREFIX/etc otherwise. Decided at install
# time, like the unit, because the prefix may be chosen then.
install(CODE "
  if(CMAKE_INSTALL_PREFIX STREQUAL \"/usr\")
    set(etc /etc)
  else()
    set(etc \"\${CMAKE_INSTALL_PREFIX}/etc\")
  endif()
  file(INSTALL \"${PROJECT_SOURCE_DIR}/config/tomomapd.toml\" DESTINATION \"\${etc}/tomomap\")
")

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME tomomap)
set(CPACK_PACKAGE_VENDOR "tomomap")
set(CPACK_PACKAGE_CONTACT "tomomap developers <tomomap@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "distributed 4-DoF registration of robots' 3D maps with tomographic features")
set(CPACK_PACKAGE_DESCRIPTION
    "tomomapd finds the transform (x, y, z, yaw) between this robot's map and its peers' maps over Fast DDS, \
without a central computer; tomomap matches, evaluates and draws maps offline.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_SET_DESTDIR ON)  # install with DESTDIR and prefix /usr, so the config lands in /etc
set(CPACK_STRIP_FILES ON)
# Dependencies from the binaries' shared libraries: Debian's runtime packages.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
configure_file(${PROJECT_SOURCE_DIR}/cmake/conffiles ${PROJECT_BINARY_DIR}/debian/conffiles COPYONLY)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${PROJECT_BINARY_DIR}/debian/conffiles)
include(CPack)
