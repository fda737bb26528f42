"""Menus as read. A price must be a whole number of pence that SQL can store: ``true`` was
read as 1p (bool is an int to Python), and 2**63 or more overflowed SQLite at the store
step. Item names are read as orderDetails.csv's, and an item on two menus (or twice on
one) is named."""

import json
import re
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


def _edit_menus(site, edit):
    path = site.root / "website" / "menus" / "menus.json"
    menus = json.loads(path.read_text())
    edit(menus)
    path.write_text(json.dumps(menus))
    return site


def test_an_item_twice_on_one_menu_is_named(tmp_path):
    # a copy-pasted line: an IndexError traceback (it looked the shop up in the shops
    # read so far, which do not hold the one being read)
    site = _edit_menus(_site_with_price(tmp_path, 100),
                       lambda m: m[1]["menu"].append(dict(m[1]["menu"][0], pence=999)))
    name = json.loads((site.root / "website" / "menus" / "menus.json").read_text()
                      )[1]["menu"][0]["item"]
    with pytest.raises(InputFormatError, match=r"menus\.json: shop 1 \(.*\): item "
                       + re.escape(repr(name)) + " is twice on its menu"):
        load_site(site)


def test_spaces_round_menu_names_are_read_past(tmp_path):
    # orderDetails.csv's values are read without them: a menu's 'Ham roll ' never
    # matched, and every order for it was invalid ('unknown item 'Ham roll'')
    def pad(m):
        m[0]["menu"][0]["item"] = f" {m[0]['menu'][0]['item']}\t"
        m[0]["location"] = f"{m[0]['location']} "

    plain = load_site(_site_with_price(tmp_path / "a", 100))
    padded = load_site(_edit_menus(_site_with_price(tmp_path / "b", 100), pad))
    assert padded.menu == plain.menu and padded.shops == plain.shops


def test_an_empty_item_name_is_named(tmp_path):
    site = _edit_menus(_site_with_price(tmp_path, 100),
                       lambda m: m[0]["menu"][0].update(item="  "))
    with pytest.raises(InputFormatError, match=r"shop 0 .*: item '  ': an item's name is "
                       "empty"):
        load_site(site)
