# SPDX-License-Identifier: GPL-3.0-or-later
"""The machine a result page was made on, as tests/bench/provenance.sh names
it: "N cores (CPU model)", and with the load average when the page is
written (the Python generators' pages)."""
import os


def cores():
    """"N cores (CPU model)": the cores this process may run on."""
    cpu = ""
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next((ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")), "")
    except OSError:
        pass
    return "%d cores (%s)" % (len(os.sched_getaffinity(0)), cpu or os.uname().machine)


def machine():
    """cores() and the load average as the page is written."""
    try:
        with open("/proc/loadavg") as fh:
            load = " ".join(fh.read().split()[:3])
    except OSError:
        load = "unknown"
    return "%s, load average %s at the end" % (cores(), load)
