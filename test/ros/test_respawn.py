#!/usr/bin/python3
"""launch/place_planner.launch respawns the node: killed, it comes back as a new
process after respawn_delay and answers goals, and the launch (this test runs in it) lives on;
with required="true" roslaunch would have taken this test down with the node."""
import math
import os
import signal
import sys
import time
import unittest
import xmlrpc.client

import actionlib
import rosgraph
import rospy
import rostest

from place_planner.msg import PlacePlanAction, PlacePlanGoal, PlacePlanResult
from mesh_messages import mesh_msg  # noqa: E402  (test/ros/mesh_messages.py)

NODE = "/place_planner"
# respawn_delay in respawn.test is 0.5 s; the rest is process start and registration.
COME_BACK = 15.0




def goal():
    g = PlacePlanGoal()
    box = [(((i & 1) - 0.5) * 0.08, (((i >> 1) & 1) - 0.5) * 0.06, (((i >> 2) & 1) - 0.5) * 0.04)
           for i in range(8)]
    g.object_mesh = mesh_msg(box, [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3),
                                   (0, 4, 6, 2), (1, 3, 7, 5)], "")
    g.placement_area_mesh = mesh_msg([(-0.2, -0.15, 0), (0.2, -0.15, 0), (0.2, 0.15, 0),
                                      (-0.2, 0.15, 0)], [(0, 1, 2, 3)], "world")
    g.object_pose.header.frame_id = "world"
    g.object_pose.pose.position.z = 0.4
    g.object_pose.pose.orientation.w = 1.0
    return g


def node_pid():
    """(pid, uri) of the node registered as NODE, or (None, None)."""
    try:
        uri = rosgraph.Master("/test_respawn").lookupNode(NODE)
        code, _, pid = xmlrpc.client.ServerProxy(uri).getPid("/test_respawn")
        return (pid, uri) if code == 1 else (None, None)
    except Exception:  # not registered, or the old URI no longer answers
        return None, None


class Respawn(unittest.TestCase):
    def plan(self):
        client = actionlib.SimpleActionClient("/place_planner/place_plan", PlacePlanAction)
        self.assertTrue(client.wait_for_server(rospy.Duration(COME_BACK)), "no action server")
        client.send_goal(goal())
        self.assertTrue(client.wait_for_result(rospy.Duration(30.0)))
        return client.get_result()

    def test_killed_node_comes_back_and_serves(self):
        deadline = time.monotonic() + COME_BACK
        pid = None
        while pid is None and time.monotonic() < deadline:
            pid, _ = node_pid()
            time.sleep(0.1)
        self.assertIsNotNone(pid, "node never registered")
        self.assertEqual(self.plan().error_code, PlacePlanResult.SUCCESS)

        os.kill(pid, signal.SIGKILL)  # a crash: no chance to clean up
        killed_at = time.monotonic()
        new_pid = None
        while time.monotonic() < killed_at + COME_BACK:
            p, _ = node_pid()
            if p is not None and p != pid:
                new_pid = p
                break
            time.sleep(0.05)
        self.assertIsNotNone(new_pid, "the node did not come back within %.0f s" % COME_BACK)
        back_after = time.monotonic() - killed_at
        r = self.plan()
        print("[respawn] pid %d killed, pid %d registered after %.2f s, first goal %s" % (
            pid, new_pid, back_after, r.error_code))
        self.assertEqual(r.error_code, PlacePlanResult.SUCCESS, r.error_message)
        self.assertTrue(r.candidates and r.candidates[0].stable)


if __name__ == "__main__":
    rospy.init_node("test_respawn")
    rostest.rosrun("place_planner", "test_respawn", Respawn, sys.argv)
