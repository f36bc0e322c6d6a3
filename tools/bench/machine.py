"""The machine a bench ran on, as the step reports name it (the tour's report lists them)."""
import os


def describe(load):
    """'CPU model, N cores, load average L' (the CPU from /proc/cpuinfo where it says)."""
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            cpu = [l.split(":", 1)[1].strip() for l in f if l.startswith("model name")][0]
    except (OSError, IndexError):
        pass
    return "%s, %d cores, load average %.1f" % (cpu, os.cpu_count(), load)
