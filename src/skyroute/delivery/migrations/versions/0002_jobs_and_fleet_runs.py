"""Long jobs and fleet runs: jobs (state, progress, result) and fleet_runs (a run's report,
events, tracks, packages and GeoJSON, and the job that made it).

Revision ID: 0002
Revises: 0001
"""

import sqlalchemy as sa
from alembic import op

revision = "0002"
down_revision = "0001"


def upgrade() -> None:
    op.create_table(
        "jobs",
        sa.Column("id", sa.String(36), primary_key=True),
        sa.Column("kind", sa.String(32), nullable=False),
        sa.Column("params", sa.JSON, nullable=False),
        sa.Column("state", sa.String(8), nullable=False, index=True),
        sa.Column("progress", sa.Float, nullable=False),
        sa.Column("result", sa.JSON),
        sa.Column("error", sa.Text),
        sa.Column("created", sa.DateTime, nullable=False),
        sa.Column("updated", sa.DateTime, nullable=False),
        sa.CheckConstraint("state in ('queued', 'running', 'done', 'failed')",
                           name="jobs_state"),
        sa.CheckConstraint("progress >= 0 and progress <= 1", name="jobs_progress"))
    op.create_table(
        "fleet_runs",
        sa.Column("id", sa.String(36), primary_key=True),
        sa.Column("job_id", sa.String(36), sa.ForeignKey("jobs.id", ondelete="SET NULL"),
                  index=True),
        sa.Column("scenario", sa.String(200), nullable=False),
        sa.Column("params", sa.JSON, nullable=False),
        sa.Column("report", sa.JSON, nullable=False),
        sa.Column("events_jsonl", sa.Text, nullable=False),
        sa.Column("tracks_csv", sa.LargeBinary, nullable=False),
        sa.Column("packages_csv", sa.Text, nullable=False),
        sa.Column("fleet_geojson", sa.Text, nullable=False),
        sa.Column("created", sa.DateTime, nullable=False))


def downgrade() -> None:
    op.drop_table("fleet_runs")
    op.drop_table("jobs")
