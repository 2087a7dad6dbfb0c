"""The host line every benchmark prints first, as bench/bench_common.h's host_description does."""
import os


def host_description():
    """CPU model, CPUs this process may use, widest vector ISA."""
    model, flags = "unknown CPU", set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() == "model name" and model == "unknown CPU":
                    model = value.strip()
                elif key.strip() == "flags" and not flags:
                    flags = set(value.split())
    except OSError:
        pass
    isa = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE2"
    return f"{model}, {len(os.sched_getaffinity(0))} CPUs, {isa}"
