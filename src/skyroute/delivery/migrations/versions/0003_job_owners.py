"""Job owners: each job names the server process that runs it (jobs.owner), and servers
(id, started, heartbeat) says which of them are alive, so a server failing orphaned jobs
leaves the live jobs of other servers on the same store alone. Jobs stored before have
no owner: no live server runs them.

Revision ID: 0003
Revises: 0002
"""

import sqlalchemy as sa
from alembic import op

revision = "0003"
down_revision = "0002"


def upgrade() -> None:
    op.add_column("jobs", sa.Column("owner", sa.String(100)))
    op.create_table(
        "servers",
        sa.Column("id", sa.String(100), primary_key=True),
        sa.Column("started", sa.DateTime, nullable=False),
        sa.Column("heartbeat", sa.DateTime, nullable=False))


def downgrade() -> None:
    op.drop_table("servers")
    op.drop_column("jobs", "owner")
