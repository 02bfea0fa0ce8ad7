# Bullet and MuJoCo physics validation, the drop-and-settle baseline and the benchmark suite.
# Included by CMakeLists.txt after catkin_package(). Bullet is used here only: never in the core.

# The Find module (not Debian's BulletConfig.cmake, whose paths are relative) gives absolute paths.
find_package(Bullet REQUIRED)
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs)
# The second engine of the placement check (mujoco_validator.h): Debian's libmujoco-dev.
find_package(mujoco REQUIRED CONFIG)

# ---------------------------------------------------------------- library
file(GLOB PP_VALIDATION_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/validation/*.cpp)
add_library(place_planner_validation STATIC ${PP_VALIDATION_SOURCES})
target_include_directories(place_planner_validation PUBLIC ${PROJECT_SOURCE_DIR}/include)
target_include_directories(place_planner_validation SYSTEM PRIVATE
  ${BULLET_INCLUDE_DIRS} ${OpenCV_INCLUDE_DIRS})
target_link_libraries(place_planner_validation
  PUBLIC place_planner_core
  PRIVATE ${BULLET_LIBRARIES} ${OpenCV_LIBS} mujoco::mujoco)
target_compile_options(place_planner_validation PRIVATE ${PP_WARN})

# ---------------------------------------------------------------- tools
foreach(tool place_planner_validate place_planner_suite)
  add_executable(${tool} src/tools/${tool}.cpp)
  target_link_libraries(${tool} place_planner_validation)
  target_compile_options(${tool} PRIVATE ${PP_WARN})
endforeach()

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
endif()

# ---------------------------------------------------------------- physics check in the product
# place_planner_cli --verify K (validation::verifyTopK); the node links it through
# place_planner_ros (cmake/node.cmake).
target_link_libraries(place_planner_cli place_planner_validation)
target_compile_definitions(place_planner_cli PRIVATE PLACE_PLANNER_HAVE_VALIDATION=1)
