"""A menu price must be a whole number of pence that SQL can store: ``true`` was read as
1p (bool is an int to Python), and 2**63 or more overflowed SQLite at the store step."""

import json
import shutil
from pathlib import Path

import pytest

from skyroute.delivery.site import load_site
from skyroute.delivery.source import DirSource
from skyroute.errors import InputFormatError

LUNCH = Path(__file__).parents[2] / "examples" / "lunch"


def _site_with_price(tmp_path, pence):
    site = tmp_path / "site"
    shutil.copytree(LUNCH / "website", site / "website")
    path = site / "website" / "menus" / "menus.json"
    menus = json.loads(path.read_text())
    menus[0]["menu"][0]["pence"] = pence
    path.write_text(json.dumps(menus))
    return DirSource(site)


@pytest.mark.parametrize("pence", [True, False, 2**63, 10**30, -1, 2.5])
def test_a_bad_price_names_the_file_and_item(tmp_path, pence):
    with pytest.raises(InputFormatError, match=r"menus\.json: shop 0 .*pence must be a whole "
                       "number >= 0"):
        load_site(_site_with_price(tmp_path, pence))


@pytest.mark.parametrize("pence", [0, 1, 2**63 - 1])
def test_a_whole_price_in_range_is_read(tmp_path, pence):
    site = load_site(_site_with_price(tmp_path, pence))
    assert pence in {p for p, _ in site.menu.values()}


@pytest.mark.parametrize("field,value,words", [
    ("item", 5, "an item's name must be a string"),
    ("name", 7, "name and location must be strings"),
    ("location", ["a", "b"], "name and location must be strings")])
def test_names_must_be_strings(tmp_path, field, value, words):
    # an item named 5 was read as "5", and the orders for it became invalid
    site = _site_with_price(tmp_path, 100)
    path = site.root / "website" / "menus" / "menus.json"
    menus = json.loads(path.read_text())
    if field == "item":
        menus[0]["menu"][0]["item"] = value
    else:
        menus[0][field] = value
    path.write_text(json.dumps(menus))
    with pytest.raises(InputFormatError, match=words):
        load_site(site)
