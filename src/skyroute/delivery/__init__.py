"""Delivery days: the lunch drone (ILP 2021 rules) from orders to a stored, validated flight."""
