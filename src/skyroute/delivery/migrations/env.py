"""Alembic environment: runs on the connection :func:`skyroute.delivery.store.init`
passes in (no alembic.ini; the package carries its migrations)."""

from alembic import context

connection = context.config.attributes["connection"]
context.configure(connection=connection)
with context.begin_transaction():
    context.run_migrations()
