"""scripts/lsan_tracer_only.py: a ctest log whose only failures are LeakSanitizer tracer crashes after
passing tests may be rerun; any test failure or sanitizer report in it may not."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts", "lsan_tracer_only.py")
PASSED = "[==========] 1 test from 1 test suite ran. (3 ms total)\n[  PASSED  ] 1 test.\n"
TRACER = ("Tracer caught signal 11: addr=0x1d50 pc=0x5629903bc04a sp=0x7f28d79fbd40\n"
          "==9551==LeakSanitizer has encountered a fatal error.\n")


def log(*blocks):
    text = "        Start 1: A.First\n"
    for i, (name, body) in enumerate(blocks, 1):
        text += f"{i}/9 Test #{i}: {name} ..........***Failed    0.36 sec\n{body}\n        Start {i + 1}: X.Next\n"
    return text + f"9/9 Test #9: X.Next ......   Passed    0.1 sec\n"


def verdict(text):
    with tempfile.NamedTemporaryFile("w", suffix=".log", delete=False) as f:
        f.write(text)
    try:
        return subprocess.run([sys.executable, SCRIPT, f.name]).returncode
    finally:
        os.unlink(f.name)


class LsanTracerOnly(unittest.TestCase):
    def test_tracer_crashes_after_passing_tests_may_rerun(self):
        self.assertEqual(verdict(log(("A.B", PASSED + TRACER), ("C.D", PASSED + TRACER))), 0)

    def test_a_failed_test_or_a_report_may_not(self):
        self.assertEqual(verdict(log(("A.B", PASSED + TRACER), ("C.D", "x.cpp:3: Failure\n[  FAILED  ] 1 test\n"))), 1)
        self.assertEqual(verdict(log(("A.B", "==1==ERROR: AddressSanitizer: heap-use-after-free\n" + PASSED + TRACER))), 1)
        self.assertEqual(verdict(log(("A.B", PASSED + "==1==ERROR: LeakSanitizer: detected memory leaks\n"))), 1)
        self.assertEqual(verdict(log(("A.B", TRACER))), 1)  # the crash came before the test passed
        self.assertEqual(verdict(log()), 1)  # nothing failed: nothing to rerun


if __name__ == "__main__":
    unittest.main()
