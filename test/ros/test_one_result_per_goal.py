#!/usr/bin/python3
"""One result message per goal (one_result_per_goal.test).

The node answers every goal exactly once, however it ends. Goals and cancels go out as raw
PlacePlanActionGoal and actionlib_msgs/GoalID messages with goal ids chosen here, and every
message on the raw result topic is recorded by goal id, so no client state machine stands
between the server and what is counted:

  1. a cancel that comes before its goal: actionlib answers RECALLED, the node's result guard
     makes the code PREEMPTED;
  2. a cancel while the goal plans: PREEMPTED;
  3. a preemption by a newer goal: the running one PREEMPTED, the newer one SUCCEEDED; a goal
     superseded while it waits (RECALLED, or PREEMPTED when it had just started); a goal
     cancelled right after it was sent;
  4. a goal in flight when the node process is killed (respawn brings the node back): it gets
     at most one result, and a goal sent to the new process exactly one.

Then actionlib's clients used the documented way (a goal is cancelled once the server has
acknowledged it: comm state PENDING or ACTIVE), for a cancel while planning, a cancel of a
waiting goal and a preemption: they must log no client error ("Got a result when we were
already in the DONE state" and the like), read from the Python log and from /rosout_agg.

Why the rule matters: actionlib's Python client (action_client.py, CommStateMachine) moves a
goal to WAITING_FOR_CANCEL_ACK as soon as cancel() is called, and a status list that arrives
then without the goal (the server has not had the goal yet: goal and cancel travel on two
topics, the status list is published at 5 Hz) marks the goal LOST (comm state DONE); the
server's one real result for it then arrives and the client logs that error. The C++ client
(comm_state_machine_imp.h) does the same.
"""
import logging
import math
import os
import signal
import sys
import threading
import time
import unittest
import xmlrpc.client

import actionlib
import rosgraph
import rospy
import rostest
from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray
from rosgraph_msgs.msg import Log

from place_planner.msg import (PlacePlanAction, PlacePlanActionGoal, PlacePlanActionResult,
                               PlacePlanGoal, PlacePlanResult)
from mesh_messages import mesh_msg  # noqa: E402  (test/ros/mesh_messages.py)

R = PlacePlanResult
S = GoalStatus
ACTION = "/place_planner/place_plan"
NODE = "/place_planner"
ANSWER = 30.0     # s, longest wait for a result
COME_BACK = 15.0  # s, respawn_delay 0.5 plus the process start and registration
GRACE = 1.0       # s, a second result would have come by then
# What actionlib's clients log when the server's messages do not fit the goal's state.
CLIENT_ERRORS = ("Got a result when we were already in the DONE state", "Transitioning goal to LOST",
                 "Invalid goal status transition", "Got an unknown status", "funny state")
STATUS_NAMES = {v: k for k, v in vars(GoalStatus).items() if k.isupper() and isinstance(v, int)}
CODE_NAMES = {v: k for k, v in vars(PlacePlanResult).items() if k.isupper() and isinstance(v, int)}




def box(sx, sy, sz):
    vertices = [(((i & 1) - 0.5) * sx, (((i >> 1) & 1) - 0.5) * sy, (((i >> 2) & 1) - 0.5) * sz)
                for i in range(8)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return vertices, faces


def plane(sx, sy):
    a, b = sx / 2, sy / 2
    return [(-a, -b, 0.0), (a, -b, 0.0), (a, b, 0.0), (-a, b, 0.0)], [(0, 1, 2, 3)]


OBJECT = mesh_msg(*box(0.08, 0.06, 0.04), "")
AREA = mesh_msg(*plane(0.4, 0.3), "world")
LONG_AREA = mesh_msg(*plane(1.0, 0.8), "world")


def base_goal():
    g = PlacePlanGoal()
    g.object_pose.header.frame_id = "world"
    g.object_pose.pose.position.x, g.object_pose.pose.position.y = 0.05, 0.02
    g.object_pose.pose.position.z = 0.4
    g.object_pose.pose.orientation.z = math.sin(0.35 / 2)
    g.object_pose.pose.orientation.w = math.cos(0.35 / 2)
    g.object_mesh = OBJECT
    return g


def quick_goal():
    """About 0.05 s of planning."""
    g = base_goal()
    g.placement_area_mesh = AREA
    return g


def long_goal():
    """Thousands of floor points: seconds of planning, time to cancel or preempt it."""
    g = base_goal()
    g.placement_area_mesh = LONG_AREA
    g.use_floor_point_spacing, g.floor_point_spacing = True, 0.01
    return g


def node_pid():
    """The pid of the process registered as NODE (its XML-RPC getPid, as rosnode does), or None."""
    try:
        uri = rosgraph.Master("/test_one_result_per_goal").lookupNode(NODE)
        code, _, pid = xmlrpc.client.ServerProxy(uri).getPid("/test_one_result_per_goal")
        return pid if code == 1 else None
    except Exception:  # not registered, or the old URI no longer answers
        return None


class ClientErrorLog(logging.Handler):
    """Keeps what actionlib's Python client logs through rospy (logger "rosout")."""

    def __init__(self):
        super().__init__(level=logging.WARNING)
        self.lines = []

    def emit(self, record):
        text = record.getMessage()
        if any(e in text for e in CLIENT_ERRORS):
            self.lines.append(text)


class OneResultPerGoal(unittest.TestCase):
    """The methods run in name order; the node is killed in the last."""

    @classmethod
    def setUpClass(cls):
        cls.lock = threading.Condition()
        cls.results = {}    # goal id -> [(status, error_code, error_message)], every message
        cls.statuses = {}   # goal id -> statuses seen in status lists
        cls.status_count = 0
        cls.rosout = []     # client errors on /rosout_agg, from any node
        cls.log = ClientErrorLog()
        logging.getLogger("rosout").addHandler(cls.log)
        cls.goal_pub = rospy.Publisher(ACTION + "/goal", PlacePlanActionGoal, queue_size=10)
        cls.cancel_pub = rospy.Publisher(ACTION + "/cancel", GoalID, queue_size=10)
        cls.result_sub = rospy.Subscriber(ACTION + "/result", PlacePlanActionResult, cls.on_result,
                                          queue_size=100)
        cls.status_sub = rospy.Subscriber(ACTION + "/status", GoalStatusArray, cls.on_status,
                                          queue_size=100)
        cls.rosout_sub = rospy.Subscriber("/rosout_agg", Log, cls.on_rosout, queue_size=100)
        cls.serial = 0

    @classmethod
    def on_result(cls, msg):
        with cls.lock:
            cls.results.setdefault(msg.status.goal_id.id, []).append(
                (msg.status.status, msg.result.error_code, msg.result.error_message))
            cls.lock.notify_all()

    @classmethod
    def on_status(cls, msg):
        with cls.lock:
            cls.status_count += 1
            for s in msg.status_list:
                cls.statuses.setdefault(s.goal_id.id, set()).add(s.status)
            cls.lock.notify_all()

    @classmethod
    def on_rosout(cls, msg):
        if any(e in msg.msg for e in CLIENT_ERRORS):
            with cls.lock:
                cls.rosout.append("%s: %s" % (msg.name, msg.msg))

    # ------------------------------------------------------------------ raw goals
    def wait_for(self, predicate, timeout):
        deadline = time.monotonic() + timeout
        with self.lock:
            while not predicate():
                left = deadline - time.monotonic()
                if left <= 0 or rospy.is_shutdown():
                    return False
                self.lock.wait(min(left, 0.05))
            return True

    def ends(self):
        return (("goal", self.goal_pub), ("cancel", self.cancel_pub), ("result", self.result_sub),
                ("status", self.status_sub))

    def missing_connections(self, new_since=None):
        """The raw topics that do not reach the server yet (with new_since: through a connection
        that is not in that list)."""
        def new(c):
            return new_since is None or all(c is not o for o in new_since)
        return [name for name, end in self.ends() if not any(new(c) for c in end.impl.connections)]

    def current_connections(self):
        """The connections now, the objects themselves: held here, a closed one is not freed, so a
        new connection cannot take its id() and pass for old."""
        return [c for _, end in self.ends() for c in end.impl.connections]

    def wait_for_server(self, new_since=None, timeout=COME_BACK):
        deadline = time.monotonic() + timeout
        while self.missing_connections(new_since):
            if time.monotonic() >= deadline:
                self.fail("the raw topics never connected to the node within %.0f s: %s" %
                          (timeout, ", ".join(self.missing_connections(new_since))))
            time.sleep(0.02)
        # The status list is latched: a message arrives once the status topic is connected.
        count = self.status_count
        self.assertTrue(self.wait_for(lambda: self.status_count > count, 5.0), "no status list")

    def new_id(self, what):
        OneResultPerGoal.serial += 1
        return "one-result/%s/%d/%d" % (what, self.serial, time.time_ns())

    def send_goal(self, goal_id, goal):
        msg = PlacePlanActionGoal()
        msg.header.stamp = rospy.Time.now()
        msg.goal_id = GoalID(id=goal_id, stamp=msg.header.stamp)
        msg.goal = goal
        self.goal_pub.publish(msg)

    def send_cancel(self, goal_id):
        self.cancel_pub.publish(GoalID(id=goal_id, stamp=rospy.Time(0)))  # as actionlib's clients do

    def wait_result(self, goal_id, timeout=ANSWER):
        self.assertTrue(self.wait_for(lambda: goal_id in self.results, timeout),
                        "no result for %s within %.0f s" % (goal_id, timeout))

    def wait_active(self, goal_id, timeout=10.0):
        self.assertTrue(self.wait_for(lambda: S.ACTIVE in self.statuses.get(goal_id, ()), timeout),
                        "%s never ACTIVE" % goal_id)
        with self.lock:
            self.assertNotIn(goal_id, self.results, "%s ended before it could be cancelled or "
                             "preempted: make the long goal longer" % goal_id)

    def check(self, expected):
        """After GRACE: each goal id in `expected` ({id: (allowed {(status, code)}, at_most_one)})
        has exactly one result message (at most one where at_most_one), an allowed one."""
        time.sleep(GRACE)
        problems = []
        with self.lock:
            for goal_id, (allowed, at_most_one) in expected.items():
                got = self.results.get(goal_id, [])
                named = ["%s/%s (%s)" % (STATUS_NAMES.get(s, s), CODE_NAMES.get(c, c), m)
                         for s, c, m in got]
                if len(got) > 1 or (not got and not at_most_one):
                    problems.append("%s: %d results %s" % (goal_id, len(got), named))
                for (s, c, m), n in zip(got, named):
                    if (s, c) not in allowed:
                        problems.append("%s: %s" % (goal_id, n))
                print("[one_result] %-48s %s" % (goal_id, ", ".join(named) or "no result"))
        self.assertEqual(problems, [])

    # ------------------------------------------------------------------ 1-3: raw goals
    def test_1_raw_goals(self):
        self.wait_for_server()
        expected = {}
        preempted = {(S.PREEMPTED, R.PREEMPTED)}
        recalled = {(S.RECALLED, R.PREEMPTED)}

        # 1. The cancel first, then its goal (a quick one: were the cancel lost it would succeed).
        x = self.new_id("cancel-before-goal")
        self.send_cancel(x)
        time.sleep(0.3)  # two topics: make sure the cancel is in first
        self.send_goal(x, quick_goal())
        self.wait_result(x)
        expected[x] = (recalled, False)
        self.assertTrue(self.results[x][0][2].startswith("recalled by actionlib"), self.results[x])

        # 2. A cancel while it plans.
        y = self.new_id("cancel-while-planning")
        self.send_goal(y, long_goal())
        self.wait_active(y)
        time.sleep(0.3)  # well into the plan (about 8 s uncancelled), not its first moments
        self.send_cancel(y)
        self.wait_result(y, 5.0)
        expected[y] = (preempted, False)

        # 3. Preempted by a newer goal.
        a, b = self.new_id("preempted"), self.new_id("preempting")
        self.send_goal(a, long_goal())
        self.wait_active(a)
        self.send_goal(b, quick_goal())
        self.wait_result(a, 5.0)
        self.wait_result(b)
        expected[a] = (preempted, False)
        expected[b] = ({(S.SUCCEEDED, R.SUCCESS)}, False)

        # 3b. Superseded while waiting: A runs, B and C back to back (B recalled, or preempted had
        # it just started), C succeeds.
        a, b, c = self.new_id("running"), self.new_id("superseded"), self.new_id("newest")
        self.send_goal(a, long_goal())
        self.wait_active(a)
        self.send_goal(b, long_goal())
        self.send_goal(c, quick_goal())
        for g in (a, b, c):
            self.wait_result(g)
        expected[a] = (preempted, False)
        expected[b] = (recalled | preempted, False)
        expected[c] = ({(S.SUCCEEDED, R.SUCCESS)}, False)

        # 3c. A goal and its cancel back to back (two topics: either may come first), while an
        # older goal runs: recalled (cancel first, or B still waiting) or preempted (B started).
        # Where the cancel came first, actionlib recalls B as it arrives, before the node sees it
        # ("recalled by actionlib ..."): nothing newer reached the node, so A plans on to its end
        # (a CI run waited 5 s for A's preemption there); otherwise B preempted A.
        a, b = self.new_id("running"), self.new_id("cancelled-at-once")
        self.send_goal(a, long_goal())
        self.wait_active(a)
        self.send_goal(b, long_goal())
        self.send_cancel(b)
        self.wait_result(b, 5.0)
        with self.lock:
            unseen = self.results[b][0][2].startswith("recalled by actionlib")
        self.wait_result(a, ANSWER if unseen else 5.0)
        expected[a] = (preempted | {(S.SUCCEEDED, R.SUCCESS)} if unseen else preempted, False)
        expected[b] = (recalled | preempted, False)

        self.check(expected)

    # ------------------------------------------------------------------ actionlib's clients
    def client_id(self, handle):
        return handle.comm_state_machine.action_goal.goal_id.id

    def wait_acknowledged(self, handle, timeout=10.0):
        """Until the server has the goal (comm state no longer WAITING_FOR_GOAL_ACK): only then
        may it be cancelled."""
        deadline = time.monotonic() + timeout
        while handle.get_comm_state() == actionlib.CommState.WAITING_FOR_GOAL_ACK:
            self.assertLess(time.monotonic(), deadline, "the goal was never acknowledged")
            time.sleep(0.002)

    def test_2_clients_the_documented_way(self):
        self.wait_for_server()
        expected = {}
        preempted = {(S.PREEMPTED, R.PREEMPTED)}
        first = actionlib.SimpleActionClient(ACTION, PlacePlanAction)
        second = actionlib.SimpleActionClient(ACTION, PlacePlanAction)
        self.assertTrue(first.wait_for_server(rospy.Duration(10.0)))
        self.assertTrue(second.wait_for_server(rospy.Duration(10.0)))

        for _ in range(3):
            # Cancel while planning: once the goal is ACTIVE.
            first.send_goal(long_goal())
            deadline = time.monotonic() + 10.0
            while first.get_state() != S.ACTIVE:
                self.assertLess(time.monotonic(), deadline, "the long goal never became active")
                time.sleep(0.002)
            first.cancel_goal()
            self.assertTrue(first.wait_for_result(rospy.Duration(5.0)))
            self.assertEqual(first.get_state(), S.PREEMPTED)
            self.assertEqual(first.get_result().error_code, R.PREEMPTED)
            expected[self.client_id(first.gh)] = (preempted, False)

            # Preemption by a newer goal from another client.
            first.send_goal(long_goal())
            deadline = time.monotonic() + 10.0
            while first.get_state() != S.ACTIVE:
                self.assertLess(time.monotonic(), deadline, "the long goal never became active")
                time.sleep(0.002)
            second.send_goal(quick_goal())
            self.assertTrue(first.wait_for_result(rospy.Duration(5.0)))
            self.assertTrue(second.wait_for_result(rospy.Duration(ANSWER)))
            self.assertEqual(first.get_state(), S.PREEMPTED)
            self.assertEqual(first.get_result().error_code, R.PREEMPTED)
            self.assertEqual(second.get_state(), S.SUCCEEDED)
            self.assertEqual(second.get_result().error_code, R.SUCCESS)
            expected[self.client_id(first.gh)] = (preempted, False)
            expected[self.client_id(second.gh)] = ({(S.SUCCEEDED, R.SUCCESS)}, False)

        # A waiting goal cancelled as soon as it is acknowledged (PENDING, or ACTIVE had it just
        # started), through the plain ActionClient; the running one is preempted by it.
        client = actionlib.ActionClient(ACTION, PlacePlanAction)
        self.assertTrue(client.wait_for_server(rospy.Duration(10.0)))
        for _ in range(3):
            running = client.send_goal(long_goal())
            deadline = time.monotonic() + 10.0
            while running.get_comm_state() != actionlib.CommState.ACTIVE:
                self.assertLess(time.monotonic(), deadline, "the long goal never became active")
                time.sleep(0.002)
            waiting = client.send_goal(long_goal())
            self.wait_acknowledged(waiting)
            waiting.cancel()
            for h in (running, waiting):
                deadline = time.monotonic() + 5.0
                while h.get_comm_state() != actionlib.CommState.DONE:
                    self.assertLess(time.monotonic(), deadline, "no answer within 5 s")
                    time.sleep(0.002)
                self.assertIsNotNone(h.get_result(), "no result: the client lost the goal")
                self.assertEqual(h.get_result().error_code, R.PREEMPTED)
            self.assertIn(waiting.get_goal_status(), (S.RECALLED, S.PREEMPTED))
            self.assertEqual(running.get_goal_status(), S.PREEMPTED)
            expected[self.client_id(running)] = (preempted, False)
            expected[self.client_id(waiting)] = ({(S.RECALLED, R.PREEMPTED)} | preempted, False)

        self.check(expected)
        with self.lock:
            errors = self.log.lines + self.rosout
        self.assertEqual(errors, [], "actionlib's clients logged errors")

    # ------------------------------------------------------------------ 4: the node killed
    def test_3_goal_in_flight_when_the_node_dies(self):
        self.wait_for_server()
        pid = node_pid()
        self.assertIsNotNone(pid, "no pid for %s" % NODE)
        before = self.current_connections()
        lost = self.new_id("in-flight-when-killed")
        self.send_goal(lost, long_goal())
        time.sleep(0.05)
        os.kill(pid, signal.SIGKILL)  # a crash: no chance to answer
        killed_at = time.monotonic()
        new_pid = None
        while new_pid is None or new_pid == pid:
            self.assertLess(time.monotonic(), killed_at + COME_BACK,
                            "the node did not come back within %.0f s" % COME_BACK)
            time.sleep(0.05)
            new_pid = node_pid()
        self.wait_for_server(new_since=before)
        print("[one_result] pid %d killed, pid %d serving %.2f s later" % (
            pid, new_pid, time.monotonic() - killed_at))
        fresh = self.new_id("after-restart")
        self.send_goal(fresh, quick_goal())
        self.wait_result(fresh)
        self.check({lost: ({(S.SUCCEEDED, R.SUCCESS), (S.PREEMPTED, R.PREEMPTED)}, True),
                    fresh: ({(S.SUCCEEDED, R.SUCCESS)}, False)})
        # Over the whole test: no goal id had more than one result message.
        with self.lock:
            self.assertEqual({k: len(v) for k, v in self.results.items() if len(v) != 1}, {})


if __name__ == "__main__":
    rospy.init_node("test_one_result_per_goal")
    rostest.rosrun("place_planner", "test_one_result_per_goal", OneResultPerGoal, sys.argv)
