"""The delivery tables: orders, order_details, deliveries, flightpath, runs.

Revision ID: 0001
Revises:
"""

import sqlalchemy as sa
from alembic import op

revision = "0001"
down_revision = None


def upgrade() -> None:
    op.create_table(
        "orders",
        sa.Column("order_no", sa.String(8), primary_key=True),
        sa.Column("delivery_date", sa.Date, nullable=False, index=True),
        sa.Column("customer", sa.String(8), nullable=False),
        sa.Column("deliver_to", sa.String(64), nullable=False))
    op.create_table(
        "order_details",
        sa.Column("order_no", sa.String(8), sa.ForeignKey("orders.order_no"),
                  primary_key=True),
        sa.Column("line", sa.Integer, primary_key=True),
        sa.Column("item", sa.String(100), nullable=False))
    op.create_table(
        "deliveries",
        sa.Column("delivery_date", sa.Date, primary_key=True),
        sa.Column("order_no", sa.String(8), primary_key=True),
        sa.Column("delivered_to", sa.String(64), nullable=False),
        sa.Column("cost_in_pence", sa.Integer, nullable=False))
    op.create_table(
        "flightpath",
        sa.Column("delivery_date", sa.Date, primary_key=True),
        sa.Column("seq", sa.Integer, primary_key=True),
        sa.Column("order_no", sa.String(8), nullable=False),
        sa.Column("from_lon", sa.Double, nullable=False),
        sa.Column("from_lat", sa.Double, nullable=False),
        sa.Column("angle", sa.Integer, nullable=False),
        sa.Column("to_lon", sa.Double, nullable=False),
        sa.Column("to_lat", sa.Double, nullable=False))
    op.create_table(
        "runs",
        sa.Column("delivery_date", sa.Date, primary_key=True),
        sa.Column("started", sa.DateTime, nullable=False),
        sa.Column("finished", sa.DateTime, nullable=False),
        sa.Column("moves", sa.Integer, nullable=False),
        sa.Column("orders_placed", sa.Integer, nullable=False),
        sa.Column("orders_delivered", sa.Integer, nullable=False),
        sa.Column("orders_invalid", sa.Integer, nullable=False),
        sa.Column("money_delivered", sa.Integer, nullable=False),
        sa.Column("money_placed", sa.Integer, nullable=False),
        sa.Column("settings", sa.Text, nullable=False))


def downgrade() -> None:
    for t in ("runs", "flightpath", "deliveries", "order_details", "orders"):
        op.drop_table(t)
