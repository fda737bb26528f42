"""The lines of each part of a fleet run's files: fleet_run_files.lines, the lines that end
in the part (its newlines, and in the file's last part one more when the file does not
end with one), so a page of a run's events is read from the parts it lies in (their
counts say which) and the events' total is a sum of counts, not a read of the whole
events.jsonl (hundreds of MB for a big run). An index of (run_id, name, part, lines)
holds the counts apart from the parts' bytes: SQLite keeps the new column after
``data`` in each row, and would walk a part's overflow pages to reach it.

The upgrade counts the lines of every stored events.jsonl, a part at a time (one read of
each, and on SQLite one rewrite of each part's row); the other files' counts stay NULL
(nothing pages them; :meth:`skyroute.jobs.store.StoredFile.lines` counts such a file as
it reads it). Runs stored from this revision on have every count.

Revision ID: 0006
Revises: 0005
"""

import sqlalchemy as sa
from alembic import op

revision = "0006"
down_revision = "0005"

INDEX = "fleet_run_files_lines"


def part_lines(data: bytes, last: bool) -> int:
    """The lines that end in a part: its newlines, one more for an unfinished last line
    (as :func:`skyroute.jobs.store.part_lines` counts them when this was written)."""
    return data.count(b"\n") + (1 if last and data and not data.endswith(b"\n") else 0)


def upgrade() -> None:
    op.add_column("fleet_run_files", sa.Column("lines", sa.Integer, nullable=True))
    c = op.get_bind()
    last = c.execute(sa.text("SELECT run_id, max(part) FROM fleet_run_files "
                             "WHERE name = 'events_jsonl' GROUP BY run_id ORDER BY run_id")
                     ).all()
    one = sa.text("SELECT data FROM fleet_run_files "
                  "WHERE run_id = :r AND name = 'events_jsonl' AND part = :k")
    put = sa.text("UPDATE fleet_run_files SET lines = :n "
                  "WHERE run_id = :r AND name = 'events_jsonl' AND part = :k")
    for run_id, n in last:
        for k in range(n + 1):  # one part at a time
            data = bytes(c.execute(one, {"r": run_id, "k": k}).scalar_one())
            c.execute(put, {"n": part_lines(data, k == n), "r": run_id, "k": k})
    op.create_index(INDEX, "fleet_run_files", ["run_id", "name", "part", "lines"])


def downgrade() -> None:
    op.drop_index(INDEX, table_name="fleet_run_files")
    op.drop_column("fleet_run_files", "lines")  # SQLite >= 3.35: ALTER TABLE DROP COLUMN
