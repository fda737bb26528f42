"""The order CSVs read without the reference data: fields every store keeps alike."""

from __future__ import annotations

import pytest

from skyroute.delivery.orders import read_csv_orders
from skyroute.errors import InputFormatError


@pytest.mark.parametrize("name, header, row, words", [
    ("orders.csv", "orderNo,deliveryDate,customer,deliverTo",
     "0000000a,2024-01-01,s2\x00,a.b.c", r"orders.csv:2: customer 's2\x00' holds a NUL"),
    ("orderDetails.csv", "orderNo,item", "0000000a,Ham\x00roll",
     r"orderDetails.csv:2: item 'Ham\x00roll' holds a NUL"),
])
def test_a_nul_character_in_a_field_is_named(tmp_path, name, header, row, words):
    # SQLite stored it; PostgreSQL refused the import ('PostgreSQL text fields cannot
    # contain NUL (0x00) bytes'), naming no file, line or field
    (tmp_path / "database").mkdir()
    files = {"orders.csv": "orderNo,deliveryDate,customer,deliverTo\n"
                           "0000000a,2024-01-01,s2,a.b.c\n",
             "orderDetails.csv": "orderNo,item\n0000000a,Ham roll\n"}
    files[name] = f"{header}\n{row}\n"
    for file, text in files.items():
        (tmp_path / "database" / file).write_text(text)
    with pytest.raises(InputFormatError) as err:
        read_csv_orders(tmp_path)
    assert words in str(err.value) and "PostgreSQL store cannot keep" in str(err.value)
