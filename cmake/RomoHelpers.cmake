# romo_add_library(<module> SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# Makes target romo_<module> (alias romo::<module>) with public headers in <module>/include.
function(romo_add_library module)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target romo_${module})
  if(ARG_SOURCES)
    add_library(${target} ${ARG_SOURCES})
    target_include_directories(${target} PUBLIC
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
      PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
    target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${module} OUTPUT_NAME romo_${module})
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} INTERFACE ${ARG_PUBLIC_DEPS})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${module})
  endif()
  add_library(romo::${module} ALIAS ${target})
  install(TARGETS ${target} EXPORT romoTargets
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/include/romo)
    install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/romo DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  endif()
endfunction()

# romo_add_gtest(<name> SOURCES ... LIBS ... [LABELS ...] [TIMEOUT s] [SERIAL])
# One executable per test file, cases discovered into CTest with the given labels; SERIAL runs
# them with nothing beside them (measurements that other processes would disturb).
function(romo_add_gtest name)
  cmake_parse_arguments(ARG "SERIAL" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} romo_test_support GTest::gtest GTest::gtest_main)
  if("unit" IN_LIST ARG_LABELS)
    add_dependencies(romo_unit_tests ${name})
  endif()
  set(serial FALSE)
  if(ARG_SERIAL)
    set(serial TRUE)
  endif()
  gtest_discover_tests(${name}
    DISCOVERY_TIMEOUT 120
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT} RUN_SERIAL ${serial})
  # Data, source and romo binary paths are compiled into romo_test_support (environment
  # variables of the same names override them): gtest_discover_tests flattens list-valued
  # ENVIRONMENT properties, so only the first entry would survive.
endfunction()
