"""A fleet scenario: airports with their runways and gates, the drone type, the package
stream and the airspace rules. Every parameter has the seed's default; files are YAML or
TOML, validated with pydantic, and an error names the file and the field.

Positions are metres north and east of the scenario's ``home`` (lat, lon), the ``ned``
frame of docs/architecture.md; runway headings are compass degrees (clockwise from
north). An airport's two runways cross at its position; each has its threshold at the
end a drone meets first (landing) or starts from (take-off). Its two gates stand beside
it, ``gate_width`` apart, or where its ``gates`` field puts them.
"""

from __future__ import annotations

import math
import re
import reprlib
import tomllib
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    FiniteFloat,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)
from pydantic.fields import FieldInfo

from skyroute.errors import InputFormatError, OptionError, check_seed, real, whole
from skyroute.files import lone_surrogate, read_text
from skyroute.fleet.limits import (
    MAX_AIRPORTS,
    MAX_AREA_KM,
    MAX_DISTANCE,
    MAX_DRONES,
    MAX_LEVELS,
    MAX_RATE,
    MAX_ZONE_CORNERS,
    MAX_ZONES,
)
from skyroute.fleet.vehicle import takeoff_phases

MAX_GATE_DISTANCE = 500.0  # metres from an airport's position to a gate it places
ROUNDING = 1e-6  # metres a gate may lie inside a limit that the default gates sit on


def _near_home(v: float) -> float:
    # an airport 1e12 m away was accepted and its flights sampled every second
    if abs(v) > MAX_DISTANCE:
        raise ValueError(f"{v:g} m from home is over the limit of {MAX_DISTANCE:,g} m")
    return v


def _declared(**keywords) -> FieldInfo:
    """JSON Schema keywords for a bound a validator of this module checks with its own
    message: the service publishes the scenario's schema (``POST /jobs/fleet``), and a
    client made from it should know every bound the server holds a value to."""
    return Field(json_schema_extra=keywords)


def _at_most(kind: type, limit: float, what: str):
    """``kind`` at most ``limit`` ("1e+07 drones is over the limit of 1,000"), declared
    as the schema's ``maximum``."""
    def check(v):
        if v > limit:
            raise ValueError(f"{v:g} {what} is over the limit of {limit:,g}")
        return v
    return Annotated[kind, AfterValidator(check), _declared(maximum=limit)]


Metres = Annotated[float, AfterValidator(_near_home),
                   _declared(minimum=-MAX_DISTANCE, maximum=MAX_DISTANCE)]
Rate = _at_most(float, MAX_RATE, "packages per hour")
Drones = _at_most(int, MAX_DRONES, "drones")
Levels = _at_most(int, MAX_LEVELS, "levels")


class _Strict(BaseModel):
    # no NaN or infinity anywhere: a NaN position or an infinite speed passed the range
    # checks and failed later with a message naming neither the file nor the field
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @field_validator("*", mode="before")
    @classmethod
    def _no_booleans(cls, v):
        # no field is a boolean, and YAML reads yes, on and true as True, which pydantic
        # took for 1 (`drones: yes` was one drone, `cruise_speed: on` 1 m/s)
        found = _first_bool(v)
        if found is not None:
            raise ValueError(f"{found} is a boolean, not valid here (YAML reads yes, no, on, "
                             "off, true and false as booleans)")
        return v

    @field_validator("*", mode="after")
    @classmethod
    def _no_nul(cls, v):
        # a name with a NUL character ran on SQLite; on PostgreSQL the service's job flew
        # the whole run and then failed to store it ('PostgreSQL text fields cannot
        # contain NUL (0x00) bytes'), a raw SQL error as the job's error
        if isinstance(v, str) and "\0" in v:
            raise ValueError(f"{v!r} holds a NUL character, which a PostgreSQL store "
                             "cannot keep")
        # a lone surrogate ("\\ud800" in JSON or YAML) ran the whole simulation, then
        # failed to be written: the CLI's report (a traceback), the service's store
        if isinstance(v, str) and (at := lone_surrogate(v)) is not None:
            raise ValueError(f"{v!r} holds U+{ord(v[at]):04X}, half of a UTF-16 surrogate "
                             "pair and no character")
        return v


def _first_bool(v) -> bool | None:
    """The first boolean in ``v`` or in its (nested) lists, or None."""
    if isinstance(v, bool):
        return v
    if isinstance(v, list | tuple):
        for x in v:
            found = _first_bool(x)
            if found is not None:
                return found
    return None


class Runway(_Strict):
    """A straight runway through its airport's position."""

    heading_deg: float = Field(ge=0, lt=360, description="compass heading of travel: "
                               "degrees clockwise from north")
    length: float = Field(default=600.0, gt=0, description="metres")


class Airport(_Strict):
    """An airport: position, a landing and a take-off runway, two gates.

    The gates stand ``gate_width`` apart beside the airport's position (see
    :func:`skyroute.fleet.flightplan.gate_position`) unless ``gates`` places them: two
    ``[north, east]`` positions in metres, in the scenario's frame like the airport's
    own, at least ``gate_width`` apart, within :data:`MAX_GATE_DISTANCE` of it and not
    on the take-off runway (:func:`_off_takeoff_runway`).
    """

    id: str = Field(min_length=1, description="unique among the scenario's airports")
    north: Metres = Field(description="metres north of home")
    east: Metres = Field(description="metres east of home")
    landing: Runway = Field(description="the runway drones land on")
    takeoff: Runway = Field(description="the runway drones take off from")
    gate_width: float = Field(default=30.0, gt=0, description="metres between gate centres")
    gates: Annotated[tuple[tuple[FiniteFloat, FiniteFloat], ...],
                     _declared(minItems=2, maxItems=2)] | None = Field(
        default=None, description="[[north, east], [north, east]] of gates 0 and 1, metres: "
        f"at least gate_width apart, each within {MAX_GATE_DISTANCE:g} m of the airport")

    @field_validator("gates")
    @classmethod
    def _gates(cls, gates, info: ValidationInfo):
        if gates is None:
            return gates
        if len(gates) != 2:
            raise ValueError(f"expected exactly two gates [[north, east], [north, east]], "
                             f"got {len(gates)}")
        known = info.data  # the fields above that validated
        if "north" in known and "east" in known:
            for k, (n, e) in enumerate(gates):
                d = math.hypot(n - known["north"], e - known["east"])
                if d > MAX_GATE_DISTANCE:
                    raise ValueError(f"gate {k} is {d:.0f} m from the airport, farther than "
                                     f"{MAX_GATE_DISTANCE:g} m")
        gap = math.hypot(gates[0][0] - gates[1][0], gates[0][1] - gates[1][1])
        width = known.get("gate_width")
        # a micrometre's slack: the default gates, written out (to_yaml of gate_position),
        # are gate_width apart give or take a rounding, and were refused as overlapping
        if width is not None and gap < width - ROUNDING:
            raise ValueError(f"gates overlapping: {gap:g} m apart, closer than gate_width "
                             f"({width:g} m)")
        if width is not None and {"north", "east", "takeoff"} <= known.keys():
            _off_takeoff_runway(gates, known["north"], known["east"], known["takeoff"], width)
        return gates


def _off_takeoff_runway(gates, north: float, east: float, takeoff: Runway,
                        width: float) -> None:
    """A ValueError naming the first gate that stands on the take-off runway: its centre
    closer than ``width / 2`` (a gate's half width: two gates closer than ``width``
    overlap) to the runway's centre line between its ends. The runway is held by one
    drone at a time, taxiing out, rolling, lifting off (docs/fleet.md's airport manager),
    and nothing books the gates against it, so a drone at such a gate stood where another
    rolled at take-off speed. The default gates stand exactly half a gate width beside
    the runway, the least allowed (:data:`ROUNDING` let through)."""
    thr, end = _ends(north, east, takeoff)
    u = (end - thr) / takeoff.length
    for k, g in enumerate(gates):
        r = np.asarray(g, dtype=float) - thr
        along = float(np.clip(r @ u, 0.0, takeoff.length))
        d = float(np.hypot(*(r - along * u)))
        if d < width / 2 - ROUNDING:
            raise ValueError(f"gate {k} stands on the take-off runway ({d:.1f} m from its "
                             f"centre line, {along:.0f} m from the threshold; less than "
                             f"half gate_width, {width / 2:g} m): a drone taking off would "
                             "roll through a drone at the gate")


class Drone(_Strict):
    """The fixed-wing type every drone of the fleet is."""

    cruise_speed: float = Field(default=50.0, gt=0, description="m/s")
    turn_radius: float = Field(default=250.0, gt=0, description="m")
    climb_angle_deg: float = Field(default=20.0, gt=0, lt=90, description="degrees above "
                                   "the horizon after the take-off roll")
    landing_speed: float = Field(default=40.0, gt=0, description="m/s at touchdown, at "
                                 "most cruise_speed")
    rollout: float = Field(default=192.0, gt=0, description="m from touchdown to a stop")
    glide_angle_deg: float = Field(default=6.0, gt=0, lt=45, description="degrees below "
                                   "the horizon on the final approach")
    taxi_speed: float = Field(default=10.0, gt=0, description="m/s on the ground")
    taxi_near_speed: float = Field(default=3.0, gt=0, description="within one gate width")
    taxi_gate_speed: float = Field(default=1.0, gt=0, description="within half a gate width")

    @model_validator(mode="after")
    def _speeds(self) -> Drone:
        if self.landing_speed > self.cruise_speed:
            raise ValueError("landing_speed must not exceed cruise_speed")
        return self


class Packages(_Strict):
    """Where packages come from: a seeded Poisson stream or an explicit CSV."""

    rate_per_hour: Rate = Field(default=60.0, ge=0, description="packages per hour, a "
                                "seeded Poisson stream")
    csv: str | None = Field(default=None, description="t,from_airport,from_gate,"
                                                      "to_airport,to_gate")


class Airspace(_Strict):
    """Cruise levels and separation minima."""

    mode: Literal["layers", "shared"] = Field("layers", description="layers: a cruise "
                                              "level per drone; shared: levels by bearing")
    sep_horizontal: float = Field(default=50.0, gt=0, description="metres")
    sep_vertical: float = Field(default=10.0, gt=0, description="metres")
    base_altitude: float = Field(default=50.0, ge=50.0, description="lowest cruise level, "
                                 "metres")
    layer_step: float = Field(default=10.0, gt=0, description="metres between levels")
    shared_levels: Levels = Field(default=4, ge=1, description="levels by direction")


class NoFlyZone(_Strict):
    """A polygon no drone may fly into: (north, east) metres, at least three corners."""

    name: str = Field(default="zone", min_length=1)
    points: list[tuple[Metres, Metres]] = Field(
        min_length=3, description="[north, east] corners, metres from home: a simple "
        f"polygon with an area (the scenario's zones hold at most {MAX_ZONE_CORNERS:,} "
        "corners in all)")

    @model_validator(mode="after")
    def _valid(self) -> NoFlyZone:
        import shapely

        poly = shapely.Polygon([(e, n) for n, e in self.points])
        if not (poly.is_valid and poly.area > 0):
            raise ValueError(f"zone {self.name!r} is not a simple polygon with an area")
        return self


class Scenario(_Strict):
    """Everything a fleet simulation needs besides the hours, seed and dispatcher."""

    name: str = "scenario"
    home_lat: float = Field(default=50.8798, ge=-90, le=90,  # Leuven
                            description="latitude of home, degrees")
    home_lon: float = Field(default=4.7005, ge=-180, le=180,
                            description="longitude of home, degrees")
    airports: list[Airport] = Field(
        min_length=2, json_schema_extra={"maxItems": MAX_AIRPORTS},
        description="farther apart than the longest runway")
    drones: Drones = Field(default=3, ge=1, description="the fleet's size")
    handover_seconds: float = Field(default=15.0, ge=0, description="at a gate: unload, "
                                    "load")
    drone: Drone = Drone()
    packages: Packages = Packages()
    airspace: Airspace = Airspace()
    no_fly_zones: list[NoFlyZone] = Field(
        default_factory=list, json_schema_extra={"maxItems": MAX_ZONES},
        description="none may cover a runway or close a ring round some airports")

    @field_validator("airports", mode="before")
    @classmethod
    def _airport_count(cls, airports):
        # counted on the input, before an airport is read (and before the distance
        # matrix of every pair): the service took the same count before parsing
        if isinstance(airports, list | tuple) and len(airports) > MAX_AIRPORTS:
            raise ValueError(f"{len(airports)} airports is over the limit of {MAX_AIRPORTS}")
        return airports

    @field_validator("airports")
    @classmethod
    def _layout(cls, airports: list[Airport]) -> list[Airport]:
        ids = [a.id for a in airports]
        if len(set(ids)) != len(ids):
            raise ValueError(f"ids must be unique, got {ids}")
        pos = np.array([[a.north, a.east] for a in airports])
        d = np.hypot(*(pos[:, None] - pos[None]).transpose(2, 0, 1))
        np.fill_diagonal(d, np.inf)
        i, j = np.unravel_index(np.argmin(d), d.shape)
        need = max(max(a.landing.length, a.takeoff.length) for a in airports)
        if d[i, j] < need:
            raise ValueError(f"{ids[i]} and {ids[j]} are {d[i, j]:.0f} m apart, closer than a "
                             f"runway ({need:g} m)")
        return airports

    @field_validator("no_fly_zones", mode="before")
    @classmethod
    def _zone_limits(cls, zones):
        # counted on the input, before a zone is read: each zone's polygon is built and
        # checked as it is read, and 125,000 zones fit in the service's 10 MB body
        if isinstance(zones, list | tuple):
            if len(zones) > MAX_ZONES:
                raise ValueError(f"{len(zones):,} zones is over the limit of {MAX_ZONES:,}")
            corners = sum(_corners(z) for z in zones)
            if corners > MAX_ZONE_CORNERS:
                raise ValueError(f"{corners:,} corners in all is over the limit of "
                                 f"{MAX_ZONE_CORNERS:,}")
        return zones

    @model_validator(mode="after")
    def _zones(self) -> Scenario:
        if self.no_fly_zones:
            import shapely

            for k, z in enumerate(self.no_fly_zones):
                poly = shapely.Polygon([(e, n) for n, e in z.points])
                for a in self.airports:
                    for rw in (a.landing, a.takeoff):
                        ends = runway_ends(a, rw)
                        if poly.intersects(shapely.LineString([(p[1], p[0]) for p in ends])):
                            raise ValueError(f"no_fly_zones[{k}]: zone {z.name!r} covers a "
                                             f"runway of airport {a.id}")
        return self

    @model_validator(mode="after")
    def _ground_rolls(self) -> Scenario:
        # a 150 m strip was accepted and drones rolled 294 m off its end on take-off and
        # 192 m on landing; the roll grows with the level, so later levels are checked
        # when a run knows its top one (skyroute.fleet.simulate)
        d = self.drone
        h = self.airspace.base_altitude
        roll = takeoff_roll(d, h)
        if roll is None:
            raise ValueError(f"drone.climb_angle_deg: {d.climb_angle_deg:g} degrees is too "
                             f"shallow: the climb to {h:g} m alone is longer than the seed's "
                             "take-off distance")
        k = short_takeoff_runway(self.airports, roll)
        if k is not None:
            raise ValueError(f"airports[{k}].takeoff.length: "
                             f"{self.airports[k].takeoff.length:g} m is shorter than the "
                             f"take-off roll ({roll:.0f} m to climb to the lowest level, "
                             f"{h:g} m)")
        for k, a in enumerate(self.airports):
            if a.landing.length < d.rollout:
                raise ValueError(f"airports[{k}].landing.length: {a.landing.length:g} m is "
                                 f"shorter than the roll-out (drone.rollout, {d.rollout:g} m)")
        return self

    def airport(self, airport_id: str) -> Airport:
        """The airport of that id."""
        for a in self.airports:
            if a.id == airport_id:
                return a
        raise OptionError(f"no airport {airport_id!r}; airports: "
                          + ", ".join(a.id for a in self.airports))


def _corners(zone) -> int:
    """The corners a zone as given (a mapping or a NoFlyZone) lists; 0 for a zone that
    is no zone (its own error comes when it is read)."""
    points = zone.get("points") if isinstance(zone, dict) else getattr(zone, "points", None)
    return len(points) if isinstance(points, list | tuple) else 0


def takeoff_roll(drone: Drone, altitude: float) -> float | None:
    """Metres of runway the take-off roll before a climb to ``altitude`` takes (the seed's
    take-off distance less the climb; it grows with the altitude), or None when the
    climb alone is longer than that distance (too shallow a ``climb_angle_deg``)."""
    try:
        return takeoff_phases(altitude, drone.climb_angle_deg, drone.landing_speed,
                              drone.cruise_speed)[0]
    except OptionError:  # no roll left: the climb alone is longer
        return None


def short_takeoff_runway(airports, roll: float) -> int | None:
    """Index of the first airport whose take-off runway is shorter than ``roll``."""
    for k, a in enumerate(airports):
        if a.takeoff.length < roll:
            return k
    return None


def load_scenario(path: str | Path) -> Scenario:
    """Read a YAML (.yaml, .yml) or TOML (.toml) scenario; errors name file and field."""
    p = Path(path)
    text = read_text(p)  # a byte-order mark (Notepad) read past
    if p.suffix.lower() == ".toml":
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise InputFormatError(p, f"not TOML: {exc}") from None
    elif p.suffix.lower() in (".yaml", ".yml"):
        import yaml

        try:
            data = yaml.load(text, Loader=_unique_keys_loader())
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            raise InputFormatError(p, f"not YAML: {getattr(exc, 'problem', exc)}",
                                   line=mark.line + 1 if mark else None) from None
    else:
        raise InputFormatError(p, f"unknown scenario type {p.suffix!r}; valid: .yaml, .yml, "
                               ".toml")
    locate = None if p.suffix.lower() == ".toml" else lambda loc: _yaml_line(text, loc)
    return _parse(data, p, locate)


def _yaml_line(text: str, loc: tuple) -> int | None:
    """The line (from 1) of the YAML ``text`` where the field at ``loc`` (a validation
    error's path: keys and list indices) is given, or of the nearest enclosing one that
    is (a missing field: its mapping's; a key from a ``<<`` merge: the mapping's)."""
    import yaml

    node, line = yaml.compose(text, Loader=_unique_keys_loader()), None
    for part in loc:
        if isinstance(node, yaml.MappingNode):
            found = next(((k, v) for k, v in node.value if isinstance(k, yaml.ScalarNode)
                          and k.value == str(part)), None)
            if found is None:
                break
            line, node = found[0].start_mark.line + 1, found[1]
        elif (isinstance(node, yaml.SequenceNode) and isinstance(part, int)
              and 0 <= part < len(node.value)):
            node = node.value[part]
            line = node.start_mark.line + 1
        else:
            break
    return line


# "airports[1].takeoff.length: ...": the field a check of several fields names first
_FIELD = re.compile(r"([A-Za-z_]\w*(?:\[\d+\]|\.[A-Za-z_]\w*)*): ")


def _loc(field: str) -> tuple:
    """``airports[1].takeoff.length`` -> ``("airports", 1, "takeoff", "length")``."""
    return tuple(int(x) if x.isdigit() else x for x in re.findall(r"\w+", field))


def _unique_keys_loader():
    """PyYAML's SafeLoader, refusing a key given twice in one mapping: it kept the last
    silently, so a second ``drones: 9`` further down overrode the first unseen. On
    LibYAML's parser where PyYAML has it (CSafeLoader: the same documents and marks;
    with the pure-Python parser a scenario of 120,000 corners took 9.5 s to be refused,
    as an error's line is found by parsing the text again; 0.5 s so)."""
    import yaml

    class UniqueKeys(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
        def construct_mapping(self, node, deep=False):
            seen = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":  # '<<: *defaults' may be
                    continue                                  # overridden key by key
                key = self.construct_object(key_node, deep=deep)
                try:
                    again = key in seen
                except TypeError:  # an unhashable key: construct_mapping names it
                    break
                if again:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"key {key!r} given twice in one mapping",
                        key_node.start_mark)
                seen.add(key)
            return super().construct_mapping(node, deep=deep)

    return UniqueKeys


def parse_scenario(data, where: str | Path = "scenario") -> Scenario:
    """A Scenario from plain data; the first error as one line naming the field. How
    long its flights stay airborne is checked by those that plan them
    (:func:`skyroute.fleet.airborne.check_flights`, which plans with this module's
    types: it sits above it)."""
    return _parse(data, where)


def _parse(data, where, locate=None) -> Scenario:
    """:func:`parse_scenario`; ``locate(loc)`` gives the line of the file where the field
    at ``loc`` is, for the error to name (``my.yaml:17: airports[1]...``)."""
    if not isinstance(data, dict):
        raise InputFormatError(where, "expected a mapping of scenario fields")
    try:
        s = Scenario.model_validate(data)
    except ValidationError as exc:
        loc, msg = first_error(exc)
        field = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in loc)
        text = f"{field.lstrip('.')}: {msg}" if field else msg
        raise InputFormatError(where, text, line=None if locate is None
                               else locate(loc)) from None
    return s


def first_error(exc: ValidationError, model: type[BaseModel] = Scenario) -> tuple[tuple, str]:
    """(field, message) of the error a scenario's reader reports of ``exc`` (``model``'s
    validation error): a misspelt key first, as "unknown key; valid: ..."; a check of
    several fields names its own field, which becomes the field (``airports[1]...``).
    The field is a path of keys and list indices; () for the scenario itself."""
    errors = exc.errors()
    # a misspelt key first: "Airports:" was reported as "airports: Field required",
    # which hid the typo that caused it
    err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc, msg = tuple(err["loc"]), err["msg"].removeprefix("Value error, ")
    if err["type"] == "extra_forbidden":  # a typo: say what the section takes
        msg = _unknown_key(loc, model)
    elif err["type"] in ("model_type", "model_attributes_type"):  # pydantic's named the
        # Python class ("instance of Drone", "object to extract fields from")
        msg = (f"expected a mapping of {'fields' if loc else 'scenario fields'}, not "
               f"{reprlib.repr(err['input'])}")
    named = None if loc else _FIELD.match(msg)
    if named:  # a check of several fields (at the model level) names its own field
        loc, msg = _loc(named.group(1)), msg[named.end():]
    return loc, msg


def _unknown_key(loc: tuple, model: type[BaseModel]) -> str:
    """"unknown key; valid: ..." for the key at ``loc`` (a validation error's path in
    ``model``), with the closest valid key first when one is close ("cruise_sped")."""
    import difflib
    import typing

    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        kinds = [model.model_fields[part].annotation]
        while kinds:  # list[Airport], Optional[Packages], Annotated[...]: the model in it
            kind = kinds.pop()
            if isinstance(kind, type) and issubclass(kind, BaseModel):
                model = kind
                break
            kinds.extend(typing.get_args(kind))
    valid = list(model.model_fields)
    close = difflib.get_close_matches(str(loc[-1]), valid, n=1)
    hint = f"did you mean {close[0]}? " if close else ""
    return f"unknown key; {hint}valid: {', '.join(valid)}"


def generate(airports: int, drones: int, *, area_km: float = 8.0, seed: int = 0,
             rate_per_hour: float | None = None) -> Scenario:
    """A valid scenario: ``airports`` spread over an ``area_km`` square (at least 1.5
    runways apart), runway headings seeded, ``drones`` drones; each within the limits of
    :mod:`skyroute.fleet.limits`."""
    # each argument named alone: a bad drone count was reported as airports=
    airports = whole("airports", airports, low=2, high=MAX_AIRPORTS,
                     need=f"2 to {MAX_AIRPORTS}")
    drones = whole("drones", drones, low=1, high=MAX_DRONES, need=f"1 to {MAX_DRONES:,}")
    area_km = real("area_km", area_km, need=f"a number > 0 and <= {MAX_AREA_KM:,g}")
    if not 0 < area_km <= MAX_AREA_KM:
        raise OptionError(f"area_km={area_km:g} must be a number > 0 and <= {MAX_AREA_KM:,g}",
                          param="area_km")
    seed = check_seed(seed)
    if rate_per_hour is not None:
        rate_per_hour = real("rate_per_hour", rate_per_hour, low=0.0, high=MAX_RATE,
                             need=f"a number >= 0 and <= {MAX_RATE:,g}")
    rng = np.random.default_rng(seed)
    size = area_km * 1000.0
    spacing = 900.0
    pts: list[np.ndarray] = []
    for _ in range(10000):
        if len(pts) == airports:
            break
        p = rng.uniform(0, size, 2)
        if all(np.hypot(*(p - q)) >= spacing for q in pts):
            pts.append(p)
    else:
        raise OptionError(f"airports={airports}: cannot place them {spacing:g} m apart in "
                          f"{area_km:g} km", param="airports")
    centre = size / 2
    ports = []
    for k, p in enumerate(pts):
        land = float(rng.integers(0, 36) * 10)
        ports.append(Airport(id=_name(k), north=round(float(p[0] - centre), 1),
                             east=round(float(p[1] - centre), 1),
                             landing=Runway(heading_deg=land),
                             takeoff=Runway(heading_deg=(land + 90) % 360)))
    rate = 20.0 * airports if rate_per_hour is None else rate_per_hour
    return Scenario(name=f"{airports}x{drones}", airports=ports, drones=drones,
                    packages=Packages(rate_per_hour=rate))


PRESETS = {  # (airports, drones, area km, rate per hour): the seed's set-ups
    "seed-3x3": (3, 3, 2.0, 60.0),
    "seed-9x9": (9, 9, 8.0, 120.0),
    "seed-18x9": (9, 18, 8.0, 180.0),
}


def preset(name: str) -> Scenario:
    """One of the seed's set-ups (:data:`PRESETS`: drones, airports, area, offered rate)."""
    if name not in PRESETS:
        raise OptionError(f"preset={name!r} is not valid; choose one of "
                          + ", ".join(repr(k) for k in PRESETS), param="preset")
    airports, drones, area, rate = PRESETS[name]
    s = generate(airports, drones, area_km=area, seed=0, rate_per_hour=rate)
    return s.model_copy(update={"name": name})


def to_yaml(s: Scenario) -> str:
    """The scenario as YAML text (every field, defaults included, ready to edit)."""
    import yaml

    return yaml.safe_dump(s.model_dump(), sort_keys=False)


def _name(k: int) -> str:
    """A, B, ..., Z, AA, AB, ..."""
    out = ""
    k += 1
    while k:
        k, r = divmod(k - 1, 26)
        out = chr(65 + r) + out
    return out


def runway_ends(a: Airport, runway: Runway) -> tuple[np.ndarray, np.ndarray]:
    """(threshold, far end) of a runway through the airport, (north, east) metres."""
    return _ends(a.north, a.east, runway)


def _ends(north: float, east: float, runway: Runway) -> tuple[np.ndarray, np.ndarray]:
    """:func:`runway_ends` of a runway centred on (``north``, ``east``)."""
    h = math.radians(runway.heading_deg)
    d = np.array([math.cos(h), math.sin(h)]) * runway.length / 2
    c = np.array([north, east])
    return c - d, c + d
