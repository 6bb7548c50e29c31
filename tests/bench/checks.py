"""The one assertion helper of the bench scripts' tests (each test is a plain script run by ctest)."""
import sys


def check(cond, what):
    """Prints `ok: what`, or `FAIL: what` and exits 1."""
    if not cond:
        print("FAIL:", what)
        sys.exit(1)
    print("ok:", what)
