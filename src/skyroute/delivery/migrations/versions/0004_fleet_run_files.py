"""A fleet run's files in a table of their own: fleet_run_files(run_id, name, data), one
row per file (``data`` its bytes, text as UTF-8), so fleet_runs keeps only what a list of
runs reads. SQLite stores a row's columns in order: reading ``created`` after 150 MB of
``tracks_csv`` walked the tracks' overflow pages (24 ms a run, for every run listed).
Every stored run's files are copied in this migration's transaction; the downgrade puts
them back.

Revision ID: 0004
Revises: 0003
"""

import sqlalchemy as sa
from alembic import op

revision = "0004"
down_revision = "0003"

FILES = ("events_jsonl", "tracks_csv", "packages_csv", "fleet_geojson")
TEXT = ("events_jsonl", "packages_csv", "fleet_geojson")  # the rest are bytes


def _as_bytes(col: str, dialect: str) -> str:
    """SQL of the column ``col`` as its UTF-8 bytes."""
    if col not in TEXT:
        return col
    return f"convert_to({col}, 'UTF8')" if dialect == "postgresql" else f"CAST({col} AS BLOB)"


def _as_text(col: str, dialect: str) -> str:
    """SQL of the bytes ``col`` read as UTF-8 text."""
    return f"convert_from({col}, 'UTF8')" if dialect == "postgresql" else f"CAST({col} AS TEXT)"


def upgrade() -> None:
    dialect = op.get_bind().dialect.name
    op.create_table(
        "fleet_run_files",
        sa.Column("run_id", sa.String(36), sa.ForeignKey("fleet_runs.id", ondelete="CASCADE"),
                  primary_key=True),
        sa.Column("name", sa.String(16), primary_key=True),
        sa.Column("data", sa.LargeBinary, nullable=False),
        sa.CheckConstraint("name in ('events_jsonl', 'tracks_csv', 'packages_csv', "
                           "'fleet_geojson')", name="fleet_run_files_name"))
    for name in FILES:
        op.execute(f"INSERT INTO fleet_run_files (run_id, name, data) "
                   f"SELECT id, '{name}', {_as_bytes(name, dialect)} FROM fleet_runs")
    with op.batch_alter_table("fleet_runs") as b:  # SQLite: a new, compact table
        for name in FILES:
            b.drop_column(name)


def downgrade() -> None:
    dialect = op.get_bind().dialect.name
    with op.batch_alter_table("fleet_runs") as b:
        b.add_column(sa.Column("events_jsonl", sa.Text))
        b.add_column(sa.Column("tracks_csv", sa.LargeBinary))
        b.add_column(sa.Column("packages_csv", sa.Text))
        b.add_column(sa.Column("fleet_geojson", sa.Text))
    for name in FILES:
        data = "data" if name not in TEXT else _as_text("data", dialect)
        op.execute(f"UPDATE fleet_runs SET {name} = (SELECT {data} FROM fleet_run_files f "
                   f"WHERE f.run_id = fleet_runs.id AND f.name = '{name}')")
    op.drop_table("fleet_run_files")
    with op.batch_alter_table("fleet_runs") as b:
        for name in FILES:
            b.alter_column(name, existing_type=sa.LargeBinary if name not in TEXT
                           else sa.Text, nullable=False)
