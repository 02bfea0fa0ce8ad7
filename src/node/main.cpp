// The place_planner node: init, construct, spin. Bad parameters: the node names them and exits 1;
// any other exception out of the node: exits 2, naming it.
#include "place_planner/ros/place_planner_node.h"

#include <algorithm>
#include <thread>
#ifdef __GLIBC__
#include <malloc.h>
#endif

int main(int argc, char** argv) {
#ifdef __GLIBC__
  // One malloc arena per core, set before any thread starts. glibc makes up to 8 per core as
  // threads contend and never frees one, so a node whose plans start threads saw its resident
  // size step up by 1-3 MB now and then over hundreds of goals; with one per core the soak's
  // readings stay within 1 % (doc/node.md, "Memory").
  mallopt(M_ARENA_MAX, static_cast<int>(std::max(2u, std::thread::hardware_concurrency())));
#endif
  ros::init(argc, argv, "place_planner");
  // Outlive the node: when the last handle goes, roscpp shuts down and with it rosconsole.
  ros::NodeHandle nh, pnh("~");
  try {
    place_planner::PlacePlannerNode node(nh, pnh);
    ros::spin();
  } catch (const std::invalid_argument& e) {
    ROS_FATAL("place_planner: %s; not starting", e.what());
    return 1;
  } catch (const std::exception& e) {
    // Goals never get here (each is answered INTERNAL_ERROR); this is the node itself failing,
    // said before launch/place_planner.launch respawns it.
    ROS_FATAL("place_planner: %s; exiting", e.what());
    return 2;
  }
  return 0;
}
