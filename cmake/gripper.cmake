# The gripper from the robot's URDF (urdfdom, no ROS): a library beside the ROS-free core, used
# by the CLI and the node; the clearance check itself is in the core (gripper.h).
find_package(urdfdom REQUIRED)
add_library(place_planner_gripper STATIC ${PROJECT_SOURCE_DIR}/src/gripper/gripper_urdf.cpp)
set_target_properties(place_planner_gripper PROPERTIES POSITION_INDEPENDENT_CODE ON)
target_include_directories(place_planner_gripper PUBLIC ${urdfdom_INCLUDE_DIRS})
target_link_libraries(place_planner_gripper PUBLIC place_planner_core ${urdfdom_LIBRARIES})
target_compile_options(place_planner_gripper PRIVATE ${PP_WARN})
