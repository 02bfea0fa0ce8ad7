// Writes a placement scene into a bag of pcl_msgs/PolygonMesh for the demo:
//   make_demo_bag OUT.bag [--area NAME|FILE] [--object NAME|FILE]
//                 [--area-frame FRAME] [--object-frame FRAME]
// NAME is a built-in scene (place_planner::scenes::byName: table, dish_rack, open_box,
// binder_stack; mug, plate, pen, cube); anything with a '.' is read as a PLY/OBJ/STL file.
// Topics: placement_area_mesh (default frame "placement_area") and object_mesh (default frame
// "": the vertices are in the object's own mesh frame), and /tf_static with the identity
// world -> area frame (so the node's tf2 lookup and rviz's fixed frame "world" both work).
// All are written as latched connections, so `rosbag play --keep-alive` serves them to nodes
// that start later.
#include <rosbag/bag.h>
#include <tf2_msgs/TFMessage.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "place_planner/infra/mesh_io.h"
#include "place_planner/infra/output_file.h"
#include "place_planner/ros/conversions.h"
#include "place_planner/infra/scenes.h"

namespace {

place_planner::Mesh load(const std::string& what) {
  if (what.find('.') != std::string::npos) return place_planner::loadMesh(what);
  return place_planner::scenes::byName(what);
}

int usage() {
  std::fprintf(stderr,
               "usage: make_demo_bag OUT.bag [--area NAME|FILE] [--object NAME|FILE]\n"
               "                     [--area-frame FRAME] [--object-frame FRAME]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return usage();
  const std::string out = argv[1];
  std::string area = "binder_stack", object = "mug", area_frame = "placement_area", object_frame;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc) return usage();
    const std::string value = argv[++i];
    if (arg == "--area") area = value;
    else if (arg == "--object") object = value;
    else if (arg == "--area-frame") area_frame = value;
    else if (arg == "--object-frame") object_frame = value;
    else return usage();
  }
  try {
    const ros::Time stamp(1.0);  // bag time; rosbag play republishes with its own clock
    // A connection header given to Bag::write replaces the generated one: it needs the type too.
    auto header = boost::make_shared<ros::M_string>();
    (*header)["callerid"] = "/make_demo_bag";
    (*header)["latching"] = "1";
    (*header)["type"] = ros::message_traits::datatype<pcl_msgs::PolygonMesh>();
    (*header)["md5sum"] = ros::message_traits::md5sum<pcl_msgs::PolygonMesh>();
    (*header)["message_definition"] = ros::message_traits::definition<pcl_msgs::PolygonMesh>();
    // The bag is written beside its destination and put in place by the output-file rules
    // (infra/output_file.h): a bag half-written, or a device replaced, is never left behind.
    place_planner::produceOutputFile(out, [&](const std::string& temp) {
    rosbag::Bag bag(temp, rosbag::bagmode::Write);
    if (!area_frame.empty() && area_frame != "world") {
      geometry_msgs::TransformStamped T;
      T.header.stamp = stamp;
      T.header.frame_id = "world";
      T.child_frame_id = area_frame;
      T.transform.rotation.w = 1.0;
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(T);
      auto tf_header = boost::make_shared<ros::M_string>(*header);
      (*tf_header)["type"] = ros::message_traits::datatype<tf2_msgs::TFMessage>();
      (*tf_header)["md5sum"] = ros::message_traits::md5sum<tf2_msgs::TFMessage>();
      (*tf_header)["message_definition"] = ros::message_traits::definition<tf2_msgs::TFMessage>();
      bag.write("/tf_static", stamp, tf, tf_header);
      std::printf("/tf_static: world -> %s (identity)\n", area_frame.c_str());
    }
    for (const auto& [topic, name, frame] :
         {std::make_tuple("placement_area_mesh", area, area_frame),
          std::make_tuple("object_mesh", object, object_frame)}) {
      const place_planner::Mesh mesh = load(name);
      pcl_msgs::PolygonMesh msg;
      place_planner::toMsg(mesh, frame, &msg);
      msg.header.stamp = msg.cloud.header.stamp = stamp;
      bag.write(topic, stamp, msg, header);
      std::printf("%s: %s, %zu vertices, %zu polygons, frame '%s'\n", topic, name.c_str(),
                  mesh.vertices.size(), mesh.patches.size(), frame.c_str());
    }
    bag.close();
    });
    std::printf("wrote %s\n", out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_demo_bag: %s\n", e.what());
    return 1;
  }
  return 0;
}
