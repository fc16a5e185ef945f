#!/usr/bin/env python3
"""Reads ctest's JUnit file (--output-junit) and says whether every failed test failed only
because LeakSanitizer's own stop-the-world tracer crashed at exit ("Tracer caught signal 11",
"LeakSanitizer has encountered a fatal error") after the test itself passed: a known sanitizer
flake (google/sanitizers#1353), seen here with Mesa's llvmpipe threads alive at exit, and no
leak report. Exit 0 when there are such failures and no others (ci/test.sh then runs them
again once); exit 1 otherwise. Prints the tests it judged, a line each."""
import sys
import xml.etree.ElementTree as ET

SIGNATURE = ("Tracer caught signal", "LeakSanitizer has encountered a fatal error")


def tracer_crash_only(output: str) -> bool:
    # The test passed (Google Test's closing line), then LSan's tracer died: no leak was found,
    # none could be looked for.
    return (all(s in output for s in SIGNATURE) and "[  PASSED  ]" in output
            and "[  FAILED  ]" not in output and "ERROR: LeakSanitizer: detected" not in output)


def main() -> int:
    if len(sys.argv) != 2:
        print("usage: lsan_tracer_crashes.py JUNIT.xml", file=sys.stderr)
        return 2
    failed = [case for case in ET.parse(sys.argv[1]).getroot().iter("testcase")
              if case.get("status") == "fail"]
    flakes = 0
    for case in failed:
        output = "".join(case.itertext())
        is_flake = tracer_crash_only(output)
        flakes += is_flake
        print(("tracer crash only: " if is_flake else "a real failure:   ") + case.get("name", "?"))
    return 0 if failed and flakes == len(failed) else 1


if __name__ == "__main__":
    sys.exit(main())
