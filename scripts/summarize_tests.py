"""Reads the JUnit XML files of catkin's run_tests and prints 'N passed, N failed, N skipped'.

Exit status: 1 when a test failed, when a test binary produced no result (crash), or when no test ran.
"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def main(results_dir):
    passed = failed = skipped = 0
    failures = []
    files = sorted(glob.glob(os.path.join(results_dir, "**", "*.xml"), recursive=True))
    for path in files:
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as e:
            failures.append("%s: unreadable result file (%s)" % (os.path.basename(path), e))
            failed += 1
            continue
        cases = root.iter("testcase")
        for case in cases:
            name = "%s.%s" % (case.get("classname", ""), case.get("name", ""))
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
                node = case.find("failure") if case.find("failure") is not None else case.find("error")
                msg = (node.get("message") or node.text or "").strip().splitlines()
                failures.append("%s: %s" % (name, msg[0] if msg else ""))
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
                sk = case.find("skipped")
                why = (sk.get("message") if sk is not None else "") or ""
                print("SKIPPED %s %s" % (name, why.strip()[:200]))
            else:
                passed += 1
    for f in failures:
        print("FAILED " + f)
    line = "%d passed, %d failed" % (passed, failed)
    if skipped:
        line += ", %d skipped" % skipped
    print(line)
    if failed or passed == 0:
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
