"""Exit 0 when every test that failed in a `ctest --output-on-failure` log failed only because
LeakSanitizer's tracer crashed at exit after the test passed (google/sanitizers#1353): its gtest
output ends "[  PASSED  ]", then "Tracer caught signal", then "LeakSanitizer has encountered a fatal
error", and holds no sanitizer report or test failure. Exit 1 otherwise (scripts/asan.sh)."""
import re
import sys

REPORTS = ("ERROR: AddressSanitizer", "runtime error:", "ERROR: LeakSanitizer: detected memory leaks",
           "[  FAILED  ]", "SUMMARY: UndefinedBehaviorSanitizer")


def failed_blocks(lines):
    """The output ctest printed under each failed test, by test name."""
    blocks, name = {}, None
    for line in lines:
        m = re.search(r"Test +#\d+: (\S+) \.+\s*\*\*\*(Failed|Exception|Timeout)", line)
        if m:
            name = m.group(1)
            blocks[name] = []
            continue
        if re.match(r"\s+Start +\d+: ", line) or re.match(r"\s*\d+/\d+ Test +#\d+: ", line):
            name = None
        elif name:
            blocks[name].append(line)
    return blocks


def tracer_crash_only(block):
    text = "".join(block)
    passed = text.find("[  PASSED  ]")
    tracer = text.find("Tracer caught signal")
    fatal = text.find("LeakSanitizer has encountered a fatal error")
    return 0 <= passed < tracer < fatal and not any(r in text for r in REPORTS)


def main():
    with open(sys.argv[1], errors="replace") as f:
        blocks = failed_blocks(f.readlines())
    return 0 if blocks and all(tracer_crash_only(b) for b in blocks.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
