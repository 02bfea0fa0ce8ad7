# The gripper from the robot's URDF (urdfdom, no ROS): a library beside the ROS-free core, used
# by the CLI and the node; the clearance check itself is in the core (gripper.h).
find_package(urdfdom REQUIRED)
add_library(place_planner_gripper STATIC ${PROJECT_SOURCE_DIR}/src/gripper/gripper_urdf.cpp)
set_target_properties(place_planner_gripper PROPERTIES POSITION_INDEPENDENT_CODE ON)
target_include_directories(place_planner_gripper PUBLIC ${urdfdom_INCLUDE_DIRS})
target_link_libraries(place_planner_gripper PUBLIC place_planner_core ${urdfdom_LIBRARIES})
target_compile_options(place_planner_gripper PRIVATE ${PP_WARN})
# The CLI takes the gripper too (--urdf, --gripper-links).
target_link_libraries(place_planner_cli place_planner_gripper)

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(gripper_tests ${PROJECT_SOURCE_DIR}/test/gripper/test_gripper.cpp
                   ${PROJECT_SOURCE_DIR}/test/core/main.cpp)
  target_link_libraries(gripper_tests place_planner_gripper)
  get_filename_component(PP_REAL_SOURCE_DIR ${PROJECT_SOURCE_DIR} REALPATH)
  target_compile_definitions(gripper_tests PRIVATE
    PP_SOURCE_DIR="${PP_REAL_SOURCE_DIR}"
    PP_SHARED_DATA_DIR="${PP_REAL_SOURCE_DIR}/../shared/data")
endif()
