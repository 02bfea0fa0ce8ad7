"""The install tree works on its own: `catkin_make install`, then, with only install/setup.bash
sourced (no devel space, no source tree on any path), rospack finds the package there,
roslaunch resolves place_planner.launch, the node comes up and advertises its action, the CLI
plans, the message modules import and a C++ program builds against the installed core.

usage: /usr/bin/python3 test/install/test_install.py RESULT_XML   (scripts/test runs it)
Writes JUnit XML for scripts/summarize_tests.py; exit status 1 when a test failed.
"""
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import unittest
from xml.sax.saxutils import quoteattr

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
WS = os.path.join(ROOT, ".build", "ws")
INSTALL = os.path.join(WS, "install")
SHARE = os.path.join(INSTALL, "share", "place_planner")


def free_port():
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def installed(command, timeout=120, env_extra=None, **kw):
    """Runs a bash command with only the install tree sourced, in a clean environment."""
    env = {"HOME": os.environ.get("HOME", "/root"), "PATH": "/usr/bin:/bin", "LANG": "C.UTF-8",
           "ROS_HOME": os.path.join(WS, "install_test_ros_home")}
    env.update(env_extra or {})
    script = "set +u; source %s/setup.bash; %s" % (INSTALL, command)
    return subprocess.run(["/bin/bash", "-c", script], env=env, cwd="/", capture_output=True, text=True,
                          timeout=timeout, **kw)


class InstallTree(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # A fresh install tree each run: nothing left from an earlier layout can make it pass.
        shutil.rmtree(INSTALL, ignore_errors=True)
        r = subprocess.run(["/bin/bash", "-c", "source scripts/common.sh; pp_build install"], cwd=ROOT,
                           capture_output=True, text=True, timeout=1800)
        cls.install_log = r.stdout[-3000:] + r.stderr[-3000:]
        cls.install_ok = r.returncode == 0

    def setUp(self):
        self.assertTrue(self.install_ok, "catkin_make install failed:\n" + self.install_log)

    def test_install_tree_has_the_package_files(self):
        for rel in ["package.xml", "launch/place_planner.launch", "launch/demo.launch",
                    "config/place_planner.yaml", "rviz/place_planner.rviz", "msg/PlacementCandidate.msg",
                    "action/PlacePlan.action"]:
            self.assertTrue(os.path.isfile(os.path.join(SHARE, rel)), rel + " not installed")
        for program in ["place_planner_node", "place_planner_cli", "make_demo_bag", "demo_client"]:
            path = os.path.join(INSTALL, "lib", "place_planner", program)
            self.assertTrue(os.access(path, os.X_OK), program + " not installed")
        for header in ["planner.h", "config.h", "infra/mesh_io.h", "search/tree_stepper.h", "judgement/stability.h", "kernels/placement_kernels.h",
                       "PlacePlanAction.h", "PlacementCandidate.h"]:
            self.assertTrue(os.path.isfile(os.path.join(INSTALL, "include", "place_planner", header)), header)
        self.assertTrue(os.path.isfile(os.path.join(INSTALL, "lib", "libplace_planner_core.a")))
        # Internal libraries' headers stay out.
        self.assertFalse(os.path.exists(os.path.join(INSTALL, "include", "place_planner", "ros")))

    def test_rospack_finds_the_installed_package(self):
        r = installed("rospack find place_planner")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(os.path.realpath(r.stdout.strip()), os.path.realpath(SHARE))

    def test_roslaunch_resolves_the_launch_file_and_node(self):
        r = installed("roslaunch --files place_planner place_planner.launch")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(os.path.realpath(r.stdout.split()[0]),
                         os.path.realpath(os.path.join(SHARE, "launch", "place_planner.launch")))
        r = installed("roslaunch --args /place_planner place_planner place_planner.launch")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(os.path.join(INSTALL, "lib", "place_planner", "place_planner_node"), r.stdout)

    def test_node_comes_up_and_advertises_its_action(self):
        port = free_port()
        env = {"ROS_MASTER_URI": "http://localhost:%d" % port}
        launch = subprocess.Popen(
            ["/bin/bash", "-c", "set +u; source %s/setup.bash; exec roslaunch -p %d place_planner "
             "place_planner.launch" % (INSTALL, port)],
            env={"HOME": os.environ.get("HOME", "/root"), "PATH": "/usr/bin:/bin", "LANG": "C.UTF-8",
                 "ROS_HOME": os.path.join(WS, "install_test_ros_home"), **env},
            cwd="/", stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        topics = ""
        try:
            deadline = time.time() + 60
            while time.time() < deadline and launch.poll() is None:
                r = installed("rostopic list", timeout=30, env_extra=env)
                topics = r.stdout
                if "/place_planner/place_plan/goal" in topics:
                    break
                time.sleep(1)
            self.assertIsNone(launch.poll(), "roslaunch ended early")
            for suffix in ["goal", "cancel", "status", "feedback", "result"]:
                self.assertIn("/place_planner/place_plan/" + suffix, topics.split())
            r = installed("rosnode list", timeout=30, env_extra=env)
            self.assertIn("/place_planner", r.stdout.split())
        finally:
            launch.send_signal(2)  # SIGINT: roslaunch stops the node and its master
            try:
                out = launch.communicate(timeout=30)[0]
            except subprocess.TimeoutExpired:
                launch.kill()
                out = launch.communicate()[0]
        self.assertIn("serving /place_planner/place_plan", out)

    def test_cli_plans_from_the_install_tree(self):
        r = installed("%s/lib/place_planner/place_planner_cli --object builtin:cube --area builtin:table "
                      "--no-robust-check --orientation principal_axis --backend cpu" % INSTALL)
        self.assertEqual(r.returncode, 0, r.stdout[-500:] + r.stderr[-500:])
        self.assertTrue(r.stdout.strip().splitlines()[-1].startswith("outcome: stable ("), r.stdout[-300:])

    def test_message_modules_import(self):
        r = installed("/usr/bin/python3 -c 'from place_planner.msg import PlacePlanAction, PlacementCandidate; "
                      "print(PlacementCandidate._type)'")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.strip(), "place_planner/PlacementCandidate")

    def test_cpp_program_builds_against_the_installed_core(self):
        src = tempfile.mkdtemp(prefix="pp_install_user_")
        try:
            with open(os.path.join(src, "CMakeLists.txt"), "w") as f:
                f.write("cmake_minimum_required(VERSION 3.16)\nproject(pp_user CXX)\n"
                        "set(CMAKE_CXX_STANDARD 17)\n"
                        "find_package(catkin REQUIRED COMPONENTS place_planner)\n"
                        "add_executable(pp_user main.cpp)\n"
                        "target_include_directories(pp_user PRIVATE ${catkin_INCLUDE_DIRS})\n"
                        "target_link_libraries(pp_user ${catkin_LIBRARIES})\n")
            with open(os.path.join(src, "main.cpp"), "w") as f:
                f.write('#include <cstdio>\n#include "place_planner/planner.h"\n#include "place_planner/infra/scenes.h"\n'
                        "int main() {\n  place_planner::PlannerConfig c;\n  c.robust_check = false;\n"
                        "  c.backend = place_planner::BackendKind::kCpu;\n"
                        "  c.orientation = place_planner::OrientationMode::kPrincipalAxis;\n"
                        "  const auto r = place_planner::Planner().plan(place_planner::scenes::box(0.05, 0.05, 0.05),\n"
                        "                                               place_planner::scenes::table(), c);\n"
                        '  std::printf("%s\\n", place_planner::toString(r.outcome()));\n'
                        "  return r.stableCount() > 0 ? 0 : 1;\n}\n")
            r = installed("cmake -S %s -B %s/build -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 "
                          "-DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null && cmake --build %s/build -j2 && "
                          "%s/build/pp_user" % (src, src, src, src), timeout=600)
            self.assertEqual(r.returncode, 0, r.stdout[-1500:] + r.stderr[-1500:])
            self.assertEqual(r.stdout.strip().splitlines()[-1], "stable")
        finally:
            shutil.rmtree(src, ignore_errors=True)


class JUnitResult(unittest.TextTestResult):
    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.cases = []

    def addSuccess(self, test):
        super().addSuccess(test)
        self.cases.append((test, None))

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self.cases.append((test, self._exc_info_to_string(err, test)))

    def addError(self, test, err):
        super().addError(test, err)
        self.cases.append((test, self._exc_info_to_string(err, test)))


def main(xml_path):
    suite = unittest.defaultTestLoader.loadTestsFromTestCase(InstallTree)
    result = unittest.TextTestRunner(resultclass=JUnitResult, verbosity=2).run(suite)
    with open(xml_path, "w") as f:
        f.write('<?xml version="1.0" encoding="UTF-8"?>\n<testsuites><testsuite name="install">\n')
        for test, failure in result.cases:
            name = test.id().split(".")[-1]
            f.write('<testcase classname="install.InstallTree" name=%s>' % quoteattr(name))
            if failure:
                first = failure.strip().splitlines()[-1]
                f.write("<failure message=%s>%s</failure>" % (quoteattr(first), failure.replace("&", "&amp;")
                                                                 .replace("<", "&lt;").replace(">", "&gt;")))
            f.write("</testcase>\n")
        f.write("</testsuite></testsuites>\n")
    return 0 if result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
