"""What magbrush's plotting scripts share: a magbrush CSV read by column, and matplotlib
without a display.

    from magbrush_plots import read_columns, pyplot
    plt = pyplot("plot_flux.py")        # None (after saying why) when matplotlib is missing
    table = read_columns("flux_residuals.csv")

The scripts are run by path (`python3 tools/plot_flux.py`), so this module is found beside them.
"""
import csv
import math
import sys


def cell_value(text):
    """A CSV cell: a number where it parses, NaN when empty, the text otherwise."""
    if text == "":
        return math.nan
    try:
        return float(text)
    except ValueError:
        return text


def read_columns(path):
    """The columns of a magbrush CSV by header name ('#' lines skipped), each a list of cell
    values (cell_value); a short row gives NaN for its missing cells. Raises OSError for a file
    that cannot be read, IndexError for one without a header."""
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
    header, data = rows[0], rows[1:]
    return {name: [cell_value(r[i]) if i < len(r) else math.nan for r in data] for i, name in enumerate(header)}


def pyplot(program):
    """matplotlib.pyplot drawing to files (the Agg backend: no display needed), or None after
    telling stderr why not: the callers then exit with status 3, which magbrush reports as a
    plot not written, not as a failed run."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        print(f"{program}: matplotlib is not available ({e}); no plot written (install python3-matplotlib)",
              file=sys.stderr)
        return None
    return plt
