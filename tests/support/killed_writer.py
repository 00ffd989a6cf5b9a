"""The real command, stopped in its write of the file named by $HOLD (its fsync: after the data,
before the rename) to be killed there: ``python -c KILLED_WRITER ARGS...`` prints "writing" when
it holds. The malformed-input corpus's test and scripts/hostile_inputs.py both kill it so."""

KILLED_WRITER = """
import os, sys, time
real_fsync = os.fsync
def hold(fd):
    real_fsync(fd)
    if os.path.basename(os.readlink(f"/proc/self/fd/{fd}")).startswith("." + os.environ["HOLD"] + "."):
        print("writing", flush=True)
        time.sleep(600)
os.fsync = hold
from fha_studio.main import main
sys.exit(main(sys.argv[1:]))
"""
