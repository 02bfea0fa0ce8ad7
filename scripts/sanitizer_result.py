"""Turns one sanitized gtest run into result files scripts/summarize_tests.py counts.

usage: sanitizer_result.py PREFIX NAME XML LOG EXIT_CODE

The gtest XML (if any) gets PREFIX. before each classname (asan.Planner.X is told apart from
the normal build's Planner.X). A sanitizer report, a crash (no XML) or a non-zero exit that
no failed test explains adds one failed test PREFIX.NAME.process with the report's first
line, in XML.process.xml: with halt_on_error the binary dies at the first report, often
before gtest writes its XML, and LeakSanitizer reports after it.
"""
import os
import re
import sys
import xml.etree.ElementTree as ET
from xml.sax.saxutils import quoteattr

MARKERS = re.compile(r"(ERROR: (Address|Leak)Sanitizer|runtime error:|WARNING: ThreadSanitizer|"
                     r"FATAL: ThreadSanitizer|SUMMARY: \w+Sanitizer)")


def main(prefix, name, xml_path, log_path, code):
    failed_tests = 0
    if os.path.exists(xml_path):
        try:
            tree = ET.parse(xml_path)
            for case in tree.getroot().iter("testcase"):
                case.set("classname", prefix + "." + case.get("classname", ""))
                if case.find("failure") is not None:
                    failed_tests += 1
            tree.write(xml_path)
        except ET.ParseError:
            os.remove(xml_path)  # half written: the process died while writing
    with open(log_path, errors="replace") as f:
        log = f.read()
    report = MARKERS.search(log)
    why = None
    if report:
        line = log[report.start():].splitlines()[0]
        why = "sanitizer report: " + line.strip()
    elif not os.path.exists(xml_path):
        tail = log.strip().splitlines()[-1:] or ["(no output)"]
        why = "no result file (crashed? exit %d): %s" % (code, tail[0])
    elif code != 0 and failed_tests == 0:
        why = "exit code %d with no failed test" % code
    if why is None:
        return 0
    with open(xml_path + ".process.xml", "w") as f:
        f.write('<?xml version="1.0" encoding="UTF-8"?>\n<testsuites><testsuite name=%s tests="1" failures="1">'
                '<testcase classname=%s name="process"><failure message=%s>see %s</failure></testcase>'
                "</testsuite></testsuites>\n"
                % (quoteattr(prefix + "." + name), quoteattr(prefix + "." + name), quoteattr(why),
                   log_path))
    print("%s %s: %s" % (prefix, name, why))
    return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5])))
