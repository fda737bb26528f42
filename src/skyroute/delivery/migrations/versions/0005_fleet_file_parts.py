"""A fleet run's files in parts of at most 1 MiB: fleet_run_files(run_id, name, part,
data), one row per part (``part`` 0, 1, ...; an empty file one empty part 0), so the
service streams a file part by part, each read one row by its key. A slice of one big
value was no answer: SQLite's ``substr`` reads the whole blob for every slice, and
PostgreSQL's ``substring`` of a compressed value decompresses it from its start, so
slicing 150 MB of tracks in 1 MiB pieces took 66 s (SQLite) and 82 s (PostgreSQL)
against 0.35 s and 3-11 s for the whole value (docs/benchmarks.md, section 10).

Every stored file is copied, one at a time (each is read whole once, as the server read
it before: 2-8 s and +310 MB on SQLite, 8-27 s and +890 MB on PostgreSQL for a run of
150 MB of tracks, on a shared machine), in this migration's transaction; the downgrade
joins the parts back.

Revision ID: 0005
Revises: 0004
"""

import sqlalchemy as sa
from alembic import op

revision = "0005"
down_revision = "0004"

PART = 1 << 20  # bytes: skyroute.jobs.store.PART_BYTES when this migration was written
NAMES = "name in ('events_jsonl', 'tracks_csv', 'packages_csv', 'fleet_geojson')"


def _files(parts: bool, table: str) -> sa.Table:
    cols = [sa.Column("run_id", sa.String(36),
                      sa.ForeignKey("fleet_runs.id", ondelete="CASCADE"), primary_key=True),
            sa.Column("name", sa.String(16), primary_key=True)]
    if parts:
        cols.append(sa.Column("part", sa.Integer, primary_key=True, autoincrement=False))
    cols.append(sa.Column("data", sa.LargeBinary, nullable=False))
    return op.create_table(table, *cols,
                           sa.CheckConstraint(NAMES, name="fleet_run_files_name"))


def _swap(new: str) -> None:
    """Drop fleet_run_files and give ``new`` its name (and, on PostgreSQL, its key's and
    foreign key's names, which Alembic made from ``new``)."""
    op.drop_table("fleet_run_files")
    op.rename_table(new, "fleet_run_files")
    if op.get_bind().dialect.name == "postgresql":
        op.execute(f"ALTER INDEX {new}_pkey RENAME TO fleet_run_files_pkey")
        op.execute(f"ALTER TABLE fleet_run_files RENAME CONSTRAINT {new}_run_id_fkey "
                   "TO fleet_run_files_run_id_fkey")


def _keys(c: sa.Connection, table: str) -> list:
    return c.execute(sa.text(f"SELECT DISTINCT run_id, name FROM {table} "
                             "ORDER BY run_id, name")).all()


def upgrade() -> None:
    c = op.get_bind()
    parts = _files(True, "fleet_run_parts")
    one = sa.text("SELECT data FROM fleet_run_files WHERE run_id = :r AND name = :n")
    for run_id, name in _keys(c, "fleet_run_files"):
        data = memoryview(c.execute(one, {"r": run_id, "n": name}).scalar_one())
        for k in range(max(1, -(-len(data) // PART))):  # one part at a time
            c.execute(parts.insert().values(run_id=run_id, name=name, part=k,
                                            data=bytes(data[k * PART:(k + 1) * PART])))
        del data
    _swap("fleet_run_parts")


def downgrade() -> None:
    c = op.get_bind()
    whole = _files(False, "fleet_run_whole")
    parts = sa.text("SELECT data FROM fleet_run_files WHERE run_id = :r AND name = :n "
                    "ORDER BY part")
    for run_id, name in _keys(c, "fleet_run_files"):
        data = b"".join(bytes(d) for d in c.execute(parts, {"r": run_id, "n": name}).scalars())
        c.execute(whole.insert().values(run_id=run_id, name=name, data=data))
        del data
    _swap("fleet_run_whole")
