"""``GET /site.geojson``: the delivery site the server was started with (``--data`` or
``--source``, read as ``deliver`` reads it), in lon/lat for the viewer's day page: the
no-fly zones, the confinement area, home, the shops, and the customers' places of every
stored order."""

from __future__ import annotations

from fastapi import APIRouter, Response

from skyroute.io.json_text import to_json
from skyroute.service.problems import responses
from skyroute.service.resources import Resources, ResourcesDep

router = APIRouter(tags=["days"])
GEOJSON = "application/geo+json"


@router.get("/site.geojson", response_class=Response,
            responses={200: {"content": {GEOJSON: {"schema": {"type": "object"}}},
                             "description": "A FeatureCollection; each feature's "
                             "`properties.kind` is no_fly_zone, confinement, home, shop or "
                             "customer."},
                       **responses(404, 503)},
            summary="The delivery site in lon/lat")
def get_site(res: ResourcesDep) -> Response:
    from skyroute.delivery.store import order_dates

    site = res.site()
    dates = order_dates(res.engine())
    key = f"site:{len(dates)}:{dates[0] if dates else ''}:{dates[-1] if dates else ''}"
    body = res.cache.get(key)  # customers come from the stored orders: keyed by their days
    if body is None:
        body = _site_doc(site, res, dates)
        res.cache[key] = body
    return Response(body, media_type=GEOJSON)


def _site_doc(site, res: Resources, dates: list) -> bytes:

    import shapely

    from skyroute.delivery.store import orders_between
    from skyroute.errors import InputFormatError

    features = []
    for poly, name in zip(site.world.obstacles, site.world.names, strict=True):
        features.append({"type": "Feature", "geometry": shapely.geometry.mapping(poly),
                         "properties": {"kind": "no_fly_zone", "name": name}})
    features.append({"type": "Feature",
                     "geometry": shapely.geometry.mapping(shapely.box(*site.confinement)),
                     "properties": {"kind": "confinement"}})
    features.append(_point(site.home, kind="home", words=site.home_words))
    for s in site.shops:
        features.append(_point(s.lonlat, kind="shop", name=s.name, words=s.words))
    eng = res.engine()
    words = sorted({o.deliver_to for v in (orders_between(eng, dates[0], dates[-1]).values()
                                           if dates else ()) for o in v})
    for w in words:
        try:
            p = site.locate(w)
        except InputFormatError:
            continue  # an order to an unknown place: GET /days/{date} gives its reason
        features.append(_point(p, kind="customer", words=w))
    doc = {"type": "FeatureCollection", "features": features}
    return to_json(doc, separators=(",", ":")).encode()


def _point(p, **props) -> dict:
    return {"type": "Feature", "geometry": {"type": "Point", "coordinates": list(p)},
            "properties": props}
