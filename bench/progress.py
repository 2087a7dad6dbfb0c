"""The benchmark scripts' progress bar with ETA: on stderr and only when it is a terminal, so that
stdout carries nothing but the results (the same bar as the C++ benchmarks' ProgressBar)."""
import sys
import time


def progress(label, fraction, started, width=30):
    """Redraws the bar for `fraction` (0..1) of the work, begun at time.monotonic() == `started`."""
    if not sys.stderr.isatty():
        return
    fraction = min(max(float(fraction), 0.0), 1.0)
    elapsed = time.monotonic() - started
    eta = f"{elapsed * (1 - fraction) / fraction:6.1f} s" if fraction > 0 else "     ? s"
    sys.stderr.write(f"\r{label:<28} [{'#' * int(width * fraction):<{width}}] {100 * fraction:5.1f}%  ETA {eta} ")
    sys.stderr.flush()


def clear():
    """Erases the bar, before a result line or at the end."""
    if sys.stderr.isatty():
        sys.stderr.write("\r\033[K")
        sys.stderr.flush()
