"""results_io.py: how a results/ script writes its files, so that a reader
never finds a half-written one (write to a temporary name, then rename).

write_text(path, text): the text file at path.
write_csv_rows(path, rows, fields): the dicts ROWS as a CSV with the columns FIELDS.
save_figure(fig, path, dpi=120): a matplotlib figure as the PNG at path.
And how it reads the project's CSV outputs:
read_csv_rows(path): the rows (dicts by column name) of a CSV whose
    provenance lines ("# key: value") come before the header.
read_csv_comments(path): (the comment lines before the header, without their "#" and
    surrounding blanks; the rows as read_csv_rows gives them).
number(text): the float in a CSV cell, NaN where it is empty or not a number.
pareto_front(points): of (cost, error, ...) tuples, the (cost, error) pairs no
    other point beats in both, cheapest first (the accuracy-cost plots).
"""
import csv
import math
import os


def write_text(path, text):
    tmp = path + ".part"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def write_csv_rows(path, rows, fields):
    tmp = path + ".part"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, path)


def save_figure(fig, path, dpi=120):
    tmp = path + ".part.png"
    fig.savefig(tmp, dpi=dpi)
    os.replace(tmp, path)


def read_csv_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def read_csv_comments(path):
    with open(path, newline="") as f:
        lines = f.readlines()
    comments = [line[1:].strip() for line in lines if line.startswith("#")]
    return comments, list(csv.DictReader(line for line in lines if not line.startswith("#")))


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def pareto_front(points):
    front = []
    for p in sorted(points, key=lambda q: (q[0], q[1])):
        if not front or p[1] < front[-1][1]:
            front.append((p[0], p[1]))
    return front
