"""The machine a measurement ran on, as the measurement pages name it: shared by the scripts that
write docs/measurements/ (each run as /usr/bin/python3 scripts/NAME.py, so this folder is on its
import path)."""
import os


def load_average():
    """The one-minute load average, as /proc/loadavg prints it."""
    with open("/proc/loadavg") as f:
        return f.read().split()[0]


def machine():
    """CPU model, cores and memory."""
    cpu = "unknown CPU"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    with open("/proc/meminfo") as f:
        mem_kib = int(f.readline().split()[1])
    return f"{cpu}, {os.cpu_count()} cores, {mem_kib / 2**20:.0f} GiB"
