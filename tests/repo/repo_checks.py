"""What the repository checks (layout.py, conventions.py) share: the report of a self-test that
planted known defects in a made-up tree, and the command line of a check.

A check is a function check(ROOT) -> list of "FILE:LINE: what" lines; a self-test plants defects,
runs the check, and hands the hits and the expected (FILE:LINE prefix, phrase) pairs to
report_planted, which prints what was missed or reported wrongly and returns the exit status.
"""
import os
import sys


def report_planted(name, expected, hits):
    """Prints the self-test's verdict on `hits` against `expected`; 0 when they match exactly."""
    def matches(h, e):
        return h.startswith(e[0]) and e[1] in h
    missing = [e[0] + " " + e[1] for e in expected if not any(matches(h, e) for h in hits)]
    extra = [h for h in hits if not any(matches(h, e) for e in expected)]
    for m in missing:
        print(f"{name} self-test: not reported: {m}")
    for x in extra:
        print(f"{name} self-test: reported wrongly: {x}")
    print(f"{name} self-test: {len(expected)} defects planted, {len(missing)} missed, "
          f"{len(extra)} false")
    return 1 if missing or extra else 0


def run_check(name, check, self_test, usage):
    """`SCRIPT SOURCE_DIR` prints each hit and "NAME: N failed"; `SCRIPT --self-test` runs the
    self-test. Returns the exit status."""
    if len(sys.argv) == 2 and sys.argv[1] == "--self-test":
        return self_test()
    if len(sys.argv) != 2:
        print(usage)
        return 2
    hits = check(os.path.abspath(sys.argv[1]))
    for h in hits:
        print(h)
    print(f"{name}: {len(hits)} failed")
    return 1 if hits else 0
