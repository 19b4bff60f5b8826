"""A station as an Eclipse SUMO network: plain XML (nodes, edges, connections, traffic lights) built by netconvert.

The export keeps the topology's rules, so SUMO can only run a vehicle where our trains can run:

* every node of the station (end, joint, turnout) is a SUMO node at its position along the line (x) and its track's
  schematic ``row`` (y);
* every track is two one-way rail edges (``allow="rail"``), ``TRACK.d`` for the down move and ``TRACK.u`` for the
  up move, each with ``length=`` the track's own length, so distances in SUMO are distances in the station;
* connections are only those of the topology's directed graph: along a joint, and through a turnout point <-> normal
  and point <-> reverse, never normal <-> reverse and never a U-turn (``--no-turnarounds``; explicit connections
  forbid every other movement from an edge);
* past each boundary an exit edge (``exit.END``) takes a train leaving the station until its rear is gone too;
* every joint where a signal stands is a plain ``traffic_light`` junction with a static program that the engine
  drives (one link per direction, ``O`` where no signal governs it). SUMO's own ``rail_signal`` would be a second
  interlocking deciding aspects by itself; ours are decided by our interlocking and only mirrored.

Turnout positions are not part of the network: a train follows the route of edges it is given, and the engine
gives it the path the turnouts' switch rails actually lie on (see :mod:`simulation.trains.sumo`).
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import quoteattr

from liansuo.rules import DARK, Aspects, load_rules
from liansuo.stations.schema import Direction
from liansuo.stations.station import Station
from liansuo.stations.topology import Move

ROW_SPACING_M = 6.0  # y distance between schematic rows
EXIT_LENGTH_M = 10_000.0  # exit edge beyond a boundary: longer than any train
EDGE_SPEED_MS = 100.0  # the network's speed limit stays out of the way (360 km/h); drivers decide speeds
NETCONVERT_OPTIONS = (
    "--no-internal-links", "true",  # no junction-internal lanes: a route is exactly the sum of its tracks
    "--no-turnarounds", "true",
    "--offset.disable-normalization", "true",
    "--geometry.remove", "false",
    "--junctions.corner-detail", "0",
    "--tls.discard-loaded", "false",
    "--no-warnings", "true",
)


class SumoUnavailable(RuntimeError):
    """SUMO (the ``sumo`` extra: libsumo and eclipse-sumo) is not installed here."""


class SumoExportError(RuntimeError):
    """netconvert could not build the network."""


@dataclass(frozen=True)
class Light:
    """A plain traffic light at a joint: its links in index order, each with the signals governing it."""

    tls: str
    node: str
    links: tuple[tuple[str, ...], ...]  # per link index: the signals that govern that move


@dataclass
class SumoNetwork:
    """An exported station: the files, and how our moves map onto SUMO edges."""

    station: str
    directory: Path
    edges: dict[Move, str]  # (track, direction) -> edge id
    exits: dict[str, str]  # boundary end -> the exit edge beyond it
    lengths: dict[str, float]  # edge id -> length (m)
    lights: list[Light]
    net_file: Path | None = None  # set once netconvert has built it
    signal_lights: dict[str, list[tuple[int, int]]] = field(default_factory=dict)  # signal -> [(light, link)]

    def edge(self, move: Move) -> str:
        return self.edges[move]

    def light_states(self, aspects: Mapping[str, str], rules: Aspects | None = None) -> dict[str, str]:
        """Every traffic light's state string for the given aspects."""
        return {light.tls: "".join(link_state(sigs, aspects, rules) for sigs in light.links) for light in self.lights}


def link_state(signals: tuple[str, ...], aspects: Mapping[str, str], rules: Aspects | None = None) -> str:
    """One link's state: ``O`` where no signal governs it, ``G`` while one of its signals shows a proceed aspect,
    ``g`` for the guide aspect (proceed at 20 km/h), ``r`` for a stop aspect or a dark signal (``rules``: the rule
    set's aspects, by default the default rule set's)."""
    if not signals:
        return "O"
    names = rules or load_rules().aspects
    seen = {aspects.get(s, DARK) for s in signals}
    if seen - names.closed - {names.guide}:
        return "G"
    return "g" if names.guide in seen else "r"


# ---- ids --------------------------------------------------------------------------------------------------------
_UNSAFE = re.compile(r"[^A-Za-z0-9_.\-]")


class _Ids:
    """SUMO-safe, unique ids for our ids (ours may contain '/')."""

    def __init__(self) -> None:
        self.used: set[str] = set()

    def make(self, wanted: str) -> str:
        base = _UNSAFE.sub("_", wanted) or "x"
        out, n = base, 1
        while out in self.used:
            n += 1
            out = f"{base}_{n}"
        self.used.add(out)
        return out


# ---- plain XML ------------------------------------------------------------------------------------------------
def _node_row(st: Station, node: str) -> float:
    tracks = st.node_tracks.get(node, [])
    if node in st.turnouts:
        tracks = [(leg, t) for leg, t in tracks if leg == "point"] or tracks
    rows = [st.tracks[t].row for _, t in tracks if st.tracks[t].row is not None]
    return float(rows[0]) if rows else 0.0  # type: ignore[arg-type]


def export_plain(station: Station, directory: Path) -> SumoNetwork:
    """Write ``station.nod.xml``, ``.edg.xml``, ``.con.xml`` and ``.tll.xml`` into ``directory``."""
    st = station
    topo = st.topology
    node_ids, edge_ids = _Ids(), _Ids()
    nodes: dict[str, str] = {n: node_ids.make(n) for n in st.node_tracks}
    coords: dict[str, tuple[float, float]] = {}
    taken: set[tuple[float, float]] = set()
    for n in st.node_tracks:
        x, y = round(st.node_at(n), 3), round(_node_row(st, n) * ROW_SPACING_M, 3)
        while (x, y) in taken:  # two nodes at one point (different rows not given): keep them apart
            y += 0.5
        taken.add((x, y))
        coords[n] = (x, y)
    signal_nodes = {s.at for s in st.model.signals if s.at in st.joints}

    node_xml = ['<nodes>']
    for n, sid in nodes.items():
        kind = "traffic_light" if n in signal_nodes else "priority"
        x, y = coords[n]
        extra = f' tl={quoteattr(sid)} tlType="static"' if kind == "traffic_light" else ""
        node_xml.append(f'  <node id={quoteattr(sid)} x="{x:g}" y="{y:g}" type="{kind}"{extra}/>')

    edges: dict[Move, str] = {}
    lengths: dict[str, float] = {}
    edge_xml = ['<edges>']

    def add_edge(eid: str, a: str, b: str, length: float) -> None:
        lengths[eid] = length
        edge_xml.append(f'  <edge id={quoteattr(eid)} from={quoteattr(a)} to={quoteattr(b)} numLanes="1" '
                        f'speed="{EDGE_SPEED_MS:g}" allow="rail" length="{length:.3f}" spreadType="center"/>')

    for tid in st.tracks:
        length = st.track_length(tid)
        lo, hi = st.track_low_port(tid).node, st.track_high_port(tid).node
        for d, a, b, suffix in ((Direction.down, lo, hi, "d"), (Direction.up, hi, lo, "u")):
            eid = edge_ids.make(f"{tid}.{suffix}")
            edges[(tid, d)] = eid
            add_edge(eid, nodes[a], nodes[b], length)

    con_xml = ['<connections>']

    def connect(a: str, b: str) -> None:
        con_xml.append(f'  <connection from={quoteattr(a)} to={quoteattr(b)} fromLane="0" toLane="0"/>')

    for (a, b) in topo.graph.edges():
        connect(edges[a], edges[b])

    exits: dict[str, str] = {}
    for end_id, end in st.ends.items():
        if end.kind.value != "boundary" or end_id not in st.node_tracks:
            continue
        track = st.node_tracks[end_id][0][1]
        outward = Direction.down if st.track_high_port(track).node == end_id else Direction.up
        x, y = coords[end_id]
        far = node_ids.make(f"far.{end_id}")
        fx = x + EXIT_LENGTH_M if outward is Direction.down else x - EXIT_LENGTH_M
        node_xml.append(f'  <node id={quoteattr(far)} x="{fx:g}" y="{y:g}" type="priority"/>')
        eid = edge_ids.make(f"exit.{end_id}")
        add_edge(eid, nodes[end_id], far, EXIT_LENGTH_M)
        exits[end_id] = eid
        connect(edges[(track, outward)], eid)

    # traffic lights: at each signal joint one link per direction, governed by the signals facing that way
    lights: list[Light] = []
    tll_xml = ['<tlLogics>']
    conns: list[str] = []
    for n in sorted(signal_nodes):
        lo, hi = st.joint_tracks(n)
        links: list[tuple[str, ...]] = []
        for index, (d, a, b) in enumerate(((Direction.down, lo, hi), (Direction.up, hi, lo))):
            links.append(tuple(s.id for s in st.signals_at(n) if s.direction is d))
            conns.append(f'  <connection from={quoteattr(edges[(a, d)])} to={quoteattr(edges[(b, d)])} fromLane="0" '
                         f'toLane="0" tl={quoteattr(nodes[n])} linkIndex="{index}"/>')
        light = Light(nodes[n], n, tuple(links))
        lights.append(light)
        state = "".join(link_state(sigs, {}) for sigs in light.links)
        tll_xml += [f'  <tlLogic id={quoteattr(nodes[n])} type="static" programID="liansuo" offset="0">',
                    f'    <phase duration="86400" state="{state}"/>', '  </tlLogic>']
    tll_xml += conns

    directory.mkdir(parents=True, exist_ok=True)
    for name, lines, close in (("nod", node_xml, "</nodes>"), ("edg", edge_xml, "</edges>"),
                               ("con", con_xml, "</connections>"), ("tll", tll_xml, "</tlLogics>")):
        text = '<?xml version="1.0" encoding="UTF-8"?>\n' + "\n".join([*lines, close]) + "\n"
        (directory / f"station.{name}.xml").write_text(text, encoding="utf-8")
    net = SumoNetwork(st.id, directory, edges, exits, lengths, lights)
    for i, light in enumerate(lights):
        for k, sigs in enumerate(light.links):
            for s in sigs:
                net.signal_lights.setdefault(s, []).append((i, k))
    return net


# ---- netconvert ------------------------------------------------------------------------------------------------
def sumo_home() -> Path:
    """Where SUMO is installed: the ``eclipse-sumo`` package (the ``sumo`` extra), else ``SUMO_HOME``."""
    try:
        import sumo  # the eclipse-sumo wheel

        return Path(sumo.SUMO_HOME)
    except ImportError:
        home = os.environ.get("SUMO_HOME")
        if home:
            return Path(home)
    raise SumoUnavailable("SUMO is not installed: pip install 'liansuo[sumo]' (libsumo and eclipse-sumo)")


def netconvert_binary() -> str:
    found = sumo_home() / "bin" / "netconvert"
    if found.exists():
        return str(found)
    which = shutil.which("netconvert")
    if which:
        return which
    raise SumoUnavailable(f"netconvert was not found in {found.parent} nor on PATH; pip install 'liansuo[sumo]'")


def run_netconvert(net: SumoNetwork, timeout_s: float = 120.0) -> Path:
    """Build ``station.net.xml`` from the plain files; SumoExportError with netconvert's own words if it fails."""
    d = net.directory
    out = d / "station.net.xml"
    cmd = [netconvert_binary(), "--node-files", str(d / "station.nod.xml"), "--edge-files",
           str(d / "station.edg.xml"), "--connection-files", str(d / "station.con.xml"),
           "--tllogic-files", str(d / "station.tll.xml"), "--output-file", str(out), *NETCONVERT_OPTIONS]
    env = dict(os.environ, SUMO_HOME=str(sumo_home()))
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s, env=env, check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise SumoExportError(f"netconvert could not run: {exc}") from exc
    if done.returncode != 0 or not out.exists():
        words = (done.stderr or done.stdout).strip().splitlines()
        raise SumoExportError(f"netconvert failed ({done.returncode}) for station {net.station}: "
                              + " | ".join(words[-8:]))
    net.net_file = out
    return out


_BUILT: dict[str, SumoNetwork] = {}
_TEMP: list[tempfile.TemporaryDirectory[str]] = []


def build_network(station: Station, directory: Path | None = None) -> SumoNetwork:
    """Export ``station`` and build it with netconvert. Without ``directory`` the result goes to a temporary
    directory and is reused for the same station data within this process."""
    if directory is not None:
        net = export_plain(station, directory)
        run_netconvert(net)
        return net
    probe = Path(tempfile.mkdtemp(prefix="liansuo-sumo-probe-"))
    try:
        export_plain(station, probe)
        digest = hashlib.sha256(b"".join((probe / f"station.{n}.xml").read_bytes()
                                         for n in ("nod", "edg", "con", "tll"))).hexdigest()
    finally:
        shutil.rmtree(probe, ignore_errors=True)
    cached = _BUILT.get(digest)
    if cached is not None and cached.net_file is not None and cached.net_file.exists():
        return cached
    tmp = tempfile.TemporaryDirectory(prefix=f"liansuo-sumo-{_UNSAFE.sub('_', station.id)}-")
    _TEMP.append(tmp)
    net = export_plain(station, Path(tmp.name))
    run_netconvert(net)
    _BUILT[digest] = net
    return net


__all__ = ["EXIT_LENGTH_M", "Light", "SumoExportError", "SumoNetwork", "SumoUnavailable", "build_network",
           "export_plain", "link_state", "netconvert_binary", "run_netconvert", "sumo_home"]
