# The ROS 1 node (a thin adapter over place_planner_core), the demo tools and the rostests.
# Included by CMakeLists.txt after catkin_package(). No PCL headers: PolygonMesh is read and
# written through sensor_msgs' PointCloud2 accessors, so nothing here needs find_package(PCL).

# ---------------------------------------------------------------- adapter library
add_library(place_planner_ros STATIC
  src/node/conversions.cpp
  src/node/markers.cpp
  src/node/params.cpp
  src/node/prepare_goal.cpp
  src/node/place_plan_server.cpp
  src/node/place_planner_node.cpp)
target_include_directories(place_planner_ros PUBLIC
  ${PROJECT_SOURCE_DIR}/include ${CATKIN_DEVEL_PREFIX}/include ${catkin_INCLUDE_DIRS})
# place_planner_validation (cmake/validation.cmake, defined after this file): verify_top_k.
# place_planner_gripper (cmake/gripper.cmake): the gripper from the URDF, loaded at startup.
target_link_libraries(place_planner_ros PUBLIC place_planner_validation place_planner_gripper
                      place_planner_core ${catkin_LIBRARIES})
target_compile_options(place_planner_ros PRIVATE ${PP_WARN})
add_dependencies(place_planner_ros ${${PROJECT_NAME}_EXPORTED_TARGETS} ${catkin_EXPORTED_TARGETS})

# ---------------------------------------------------------------- node and tools
add_executable(place_planner_node src/node/main.cpp)
target_link_libraries(place_planner_node place_planner_ros)
target_compile_options(place_planner_node PRIVATE ${PP_WARN})

add_executable(make_demo_bag src/tools/make_demo_bag.cpp)
target_link_libraries(make_demo_bag place_planner_ros)
target_compile_options(make_demo_bag PRIVATE ${PP_WARN})

add_executable(demo_client src/tools/demo_client.cpp)
target_link_libraries(demo_client place_planner_ros)
target_compile_options(demo_client PRIVATE ${PP_WARN})

# ---------------------------------------------------------------- rostests
if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)
  add_rostest_gtest(place_planner_node_test test/ros/place_planner_node.test
    test/ros/test_place_planner_node.cpp)
  target_link_libraries(place_planner_node_test place_planner_ros)
  add_dependencies(place_planner_node_test place_planner_node)
  # The test starts the node itself once, with a bad parameter, to see it refuse.
  target_compile_definitions(place_planner_node_test PRIVATE
    PP_NODE_BINARY="$<TARGET_FILE:place_planner_node>")

  # The soak (scripts/soak, python): the short form, 60 goals of every kind.
  add_rostest(test/ros/soak.test DEPENDENCIES place_planner_node)

  # One result message per goal id (raw goals and cancels, a node killed mid-goal), and clients
  # that cancel only what the server has acknowledged (test_one_result_per_goal.py).
  add_rostest(test/ros/one_result_per_goal.test DEPENDENCIES place_planner_node)

  # launch/place_planner.launch respawns a killed node (test_respawn.py).
  add_rostest(test/ros/respawn.test DEPENDENCIES place_planner_node)

  # prepareGoal without a node: a plain gtest, no roscore (goal -> core conversion, frames,
  # overrides, errors naming the field).
  catkin_add_gtest(prepare_goal_tests test/ros/test_prepare_goal.cpp)
  target_link_libraries(prepare_goal_tests place_planner_ros)
  target_compile_options(prepare_goal_tests PRIVATE ${PP_WARN})

  # The result guard of PlacePlanServer, no roscore.
  catkin_add_gtest(place_plan_server_tests test/ros/test_place_plan_server.cpp)
  target_link_libraries(place_plan_server_tests place_planner_ros)
  target_compile_options(place_plan_server_tests PRIVATE ${PP_WARN})

  # The command-line tool's exit codes and outcome line (no ROS master needed): it runs the
  # built binary.
  catkin_add_gtest(cli_tests test/ros/test_cli.cpp)
  target_link_libraries(cli_tests place_planner_core)
  add_dependencies(cli_tests place_planner_cli)
  target_compile_definitions(cli_tests PRIVATE PP_CLI_BINARY="$<TARGET_FILE:place_planner_cli>")
endif()
