# `cmake --install`: the binaries, the systemd unit, the default configuration and the
# install notes (deploy/README.md). The unit and the configuration directory follow the
# prefix given at install time (InstallDeploy.cmake).
include(GNUInstallDirs)

install(TARGETS omnislam RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET omnislamd)
  install(TARGETS omnislamd RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs DESTINATION ${CMAKE_INSTALL_DOCDIR})  # the README links into it
install(FILES ${PROJECT_SOURCE_DIR}/deploy/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} RENAME deploy.md)
install(CODE "set(OMNISLAM_DEPLOY_DIR \"${PROJECT_SOURCE_DIR}/deploy\")
set(OMNISLAM_STAGING_DIR \"${PROJECT_BINARY_DIR}/deploy-staging\")
set(OMNISLAM_BINDIR \"${CMAKE_INSTALL_BINDIR}\")")
install(SCRIPT ${CMAKE_CURRENT_LIST_DIR}/InstallDeploy.cmake)
