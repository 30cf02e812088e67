"""results_io.py: how a results/ script writes its files, so that a reader
never finds a half-written one (write to a temporary name, then rename).

write_text(path, text): the text file at path.
save_figure(fig, path, dpi=120): a matplotlib figure as the PNG at path.
"""
import os


def write_text(path, text):
    tmp = path + ".part"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def save_figure(fig, path, dpi=120):
    tmp = path + ".part.png"
    fig.savefig(tmp, dpi=dpi)
    os.replace(tmp, path)
