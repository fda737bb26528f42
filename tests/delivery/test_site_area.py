"""``website/area.json``, a data set's own home and confinement: a box that is wrong on
its own is named as area.json's, not as the zones file's that the world is read from."""

from __future__ import annotations

import json
import shutil

import pytest

from skyroute.delivery.site import load_site
from skyroute.delivery.source import DirSource
from skyroute.errors import InputFormatError
from tests.conftest import ROOT

EXAMPLE = ROOT / "examples" / "lunch"
BOX = [-3.17, 55.969, -3.1618, 55.9726]  # the example's


@pytest.mark.parametrize("box, words", [
    # (lat, lon) for (lon, lat): "no-fly-zones.geojson: the boundary lies 7,841 km
    # from the rest of the world"
    ([55.969, -3.17, 55.9726, -3.1618], "home 'pebble.blade.nectar' at (-3.168556, "
     "55.970552) is not inside the confinement [55.969, -3.17, 55.9726, -3.1618]"),
    ([-180, -90, 180, 90], "the boundary spans lon -180 to 180"),
    ([-3.17, 55.969, -3.1618, 95.0], "a corner of the confinement (-3.1618, 95) is not "
     "a place"),
    ([float("-inf"), 55.969, -3.1618, 55.9726], "expected {\"home\": WORDS, "
     "\"confinement\": [min_lon, min_lat, max_lon, max_lat]}"),
])
def test_a_wrong_confinement_names_area_json(tmp_path, box, words):
    shutil.copytree(EXAMPLE / "website", tmp_path / "website")
    path = tmp_path / "website" / "area.json"
    area = json.loads(path.read_text())
    area["confinement"] = box
    path.write_text(json.dumps(area))
    with pytest.raises(InputFormatError) as err:
        load_site(DirSource(tmp_path))
    assert err.value.path == str(path) and words in err.value.reason, str(err.value)


def test_the_examples_area_is_read(tmp_path):
    site = load_site(DirSource(EXAMPLE))
    assert list(site.confinement) == BOX
