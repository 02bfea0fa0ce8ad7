# Bullet physics validation, the drop-and-settle baseline and the benchmark suite (issue 5).
# Included by CMakeLists.txt after catkin_package(). Bullet is used here only: never in the core.

# The Find module (not Debian's BulletConfig.cmake, whose paths are relative) gives absolute paths.
find_package(Bullet REQUIRED)
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs)

# ---------------------------------------------------------------- library
file(GLOB PP_VALIDATION_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/validation/*.cpp)
add_library(place_planner_validation STATIC ${PP_VALIDATION_SOURCES})
target_include_directories(place_planner_validation PUBLIC ${PROJECT_SOURCE_DIR}/include)
target_include_directories(place_planner_validation SYSTEM PRIVATE
  ${BULLET_INCLUDE_DIRS} ${OpenCV_INCLUDE_DIRS})
target_link_libraries(place_planner_validation
  PUBLIC place_planner_core
  PRIVATE ${BULLET_LIBRARIES} ${OpenCV_LIBS})
target_compile_options(place_planner_validation PRIVATE ${PP_WARN})

# ---------------------------------------------------------------- tools
# They call Planner::plan; built once a core source defines it (the planner lands separately).
set(PP_VALIDATION_HAVE_PLANNER OFF)
file(GLOB PP_VALIDATION_CORE_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/core/*.cpp)
foreach(f ${PP_VALIDATION_CORE_SOURCES})
  file(STRINGS ${f} pp_hit REGEX "Planner::plan\\(")
  if(pp_hit)
    set(PP_VALIDATION_HAVE_PLANNER ON)
  endif()
endforeach()
if(PP_VALIDATION_HAVE_PLANNER)
  foreach(tool place_planner_validate place_planner_suite)
    if(EXISTS ${PROJECT_SOURCE_DIR}/src/tools/${tool}.cpp)
      add_executable(${tool} src/tools/${tool}.cpp)
      target_link_libraries(${tool} place_planner_validation)
      target_compile_options(${tool} PRIVATE ${PP_WARN})
    endif()
  endforeach()
else()
  message(STATUS "place_planner: Planner::plan not defined yet, validation tools not built")
endif()

# ---------------------------------------------------------------- tests (validator + smoke suite)
if(CATKIN_ENABLE_TESTING)
  file(GLOB PP_VALIDATION_TESTS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/validation/*.cpp)
  catkin_add_gtest(validation_tests ${PP_VALIDATION_TESTS})
  target_link_libraries(validation_tests place_planner_validation)
  target_compile_options(validation_tests PRIVATE ${PP_WARN})
  get_filename_component(PP_VALIDATION_REAL_SOURCE_DIR ${PROJECT_SOURCE_DIR} REALPATH)
  target_compile_definitions(validation_tests PRIVATE
    PP_SOURCE_DIR="${PP_VALIDATION_REAL_SOURCE_DIR}"
    PP_SHARED_DATA_DIR="${PP_VALIDATION_REAL_SOURCE_DIR}/../shared/data")
  if(PP_VALIDATION_HAVE_PLANNER)
    target_compile_definitions(validation_tests PRIVATE PP_VALIDATION_HAVE_PLANNER=1)
  endif()
endif()
