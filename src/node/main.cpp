// The place_planner node: init, construct, spin. Bad parameters: the node names them and exits 1.
#include "place_planner/ros/place_planner_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "place_planner");
  // Outlive the node: when the last handle goes, roscpp shuts down and with it rosconsole.
  ros::NodeHandle nh, pnh("~");
  try {
    place_planner::PlacePlannerNode node(nh, pnh);
    ros::spin();
  } catch (const std::invalid_argument& e) {
    ROS_FATAL("place_planner: %s; not starting", e.what());
    return 1;
  }
  return 0;
}
