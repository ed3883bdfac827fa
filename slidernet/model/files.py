"""Network files: GraphML and edge lists (with their node files), read into networkx graphs and written.

:func:`read_graph` reads a file into a graph that
:func:`~slidernet.model.builders.from_graph` turns into a network;
:func:`write_graph` writes a network to a file that it reads back bit for
bit. Each reader reads a file whole or not at all: a row (of an edge list or
a node file) with a field missing or one too many, a field that is not a
number (:func:`slidernet._validation.read_real`, the rule of every data file),
a GraphML attribute that is not a number or not one slidernet knows, a node
without the ``y`` the others have, a spring listed twice (a GraphML parallel
edge, or both directions of a directed graph, as an edge list listing it
twice) or joining a node to itself: each is refused with the file and the
line, or the element, where it stands. An empty cell of a CSV file takes the
default of its column (the header names the columns a row fills). The
formats, with example files, are in ``docs/guides/file-formats.md``.
"""

from __future__ import annotations

import ast
import csv
import io
from collections.abc import Iterator, Mapping
from os import PathLike
from pathlib import Path
from typing import Any
from xml.etree.ElementTree import ParseError

import networkx as nx
import numpy as np

from slidernet._validation import read_real
from slidernet.errors import ConfigError, param_error
from slidernet.model.network import Network

__all__ = ["NODE_ATTRIBUTES", "SPRING_ATTRIBUTES", "graph_files", "read_graph", "write_graph"]

_EDGE_LIST_SUFFIXES = (".edgelist", ".txt", ".csv")
_GRAPH_SUFFIXES = (".graphml", *_EDGE_LIST_SUFFIXES)

#: What a spring of a file may carry (each a number; absent: the network's default).
SPRING_ATTRIBUTES = ("k", "kappa", "rest_length")
#: What a node of a GraphML file may carry (each a number): its position in l0, its normal load in N and its
#: external force in N (``f_ext`` along x, or ``f_ext_x`` and ``f_ext_y``: GraphML attributes are scalars).
NODE_ATTRIBUTES = ("x", "y", "normal_load", "f_ext", "f_ext_x", "f_ext_y")
# GraphML's own: an edge's id (networkx reads it as an attribute), and 'pos', which GraphML can only hold as
# text and which x and y replace.
_GRAPHML_IGNORED = {"node": ("pos",), "edge": ("id",)}


def _suffix(path: Path, owner: str) -> str:
    suffix = path.suffix.lower()
    if suffix not in _GRAPH_SUFFIXES:
        raise ConfigError(
            f"{owner} cannot handle {str(path)!r}: unknown extension {path.suffix!r}; "
            f"expected one of {', '.join(_GRAPH_SUFFIXES)}."
        )
    return suffix


def _nodes_file(path: Path) -> Path:
    """The companion node file of an edge list: ``net.edgelist`` -> ``net.nodes.csv``."""
    return path.with_name(path.stem + ".nodes.csv")


def graph_files(path: str | PathLike[str]) -> dict[str, Path]:
    """The files :func:`read_graph` reads for ``path`` without ``positions`` (as a configuration reads it).

    Returns
    -------
    dict of str to Path
        ``"graph"``: the file itself; ``"nodes"``: an edge list's companion
        node file (``<stem>.nodes.csv``), where the file is an edge list.
    """
    p = Path(path)
    files = {"graph": p}
    if p.suffix.lower() != ".graphml":
        files["nodes"] = _nodes_file(p)
    return files


def read_graph(path: str | PathLike[str], positions: Any = None) -> nx.Graph:
    """Read a network file into a networkx graph that :func:`~slidernet.model.builders.from_graph` accepts.

    Formats, chosen by extension:

    ``.graphml``
        GraphML (networkx.read_graphml). GraphML cannot store tuples, so
        positions are node attributes ``x`` and ``y`` (in l0; only ``x`` in
        1D, and then on every node). Optional: ``normal_load``, ``f_ext``
        (or ``f_ext_x``, ``f_ext_y``) on nodes; ``k``, ``kappa``,
        ``rest_length`` on edges; any other attribute is refused (a typo
        would otherwise be a default). Each is a number, typed (``double``)
        or written as text. Node ids that are all integers become ints.
        Nodes keep the file's order; a directed graph is read undirected,
        and a spring given twice (two parallel edges, or both directions)
        is refused.
    ``.edgelist``, ``.txt``
        One spring per line, ``i j`` (integer node ids) then either nothing,
        ``key=value`` tokens (``0 1 k=2.0 kappa=0.5``) or a Python dict (the
        format of networkx.write_edgelist: ``0 1 {'k': 2.0}``); keys among
        ``k``, ``kappa``, ``rest_length``, each at most once. ``#`` starts a
        comment.
    ``.csv``
        CSV edge list with a header: ``i,j`` (or ``source,target``), then
        optional columns ``k``, ``kappa``, ``rest_length``; every row has
        one field per column, and an empty field takes the default.

    Edge lists carry no positions: they come from ``positions`` or else from
    the companion file ``<stem>.nodes.csv`` next to the edge list, a CSV with
    header ``node,x[,y][,normal_load]`` (positions in l0, loads in N; every
    row one field per column, ``x`` and ``y`` never empty). The
    nodes are numbered in the order of that file (or 0..N-1 for
    ``positions``); every spring must join two listed nodes, at most once.
    :func:`~slidernet.model.builders.from_graph` numbers the springs in
    ``G.edges`` order, which is the file's order when the file lists them
    sorted by (i, j) with i < j (as :func:`write_graph` does).

    Parameters
    ----------
    path : str or path-like
        The file to read.
    positions : array_like, shape (N,) or (N, 2), optional
        Positions in l0 of the nodes in graph order (node id i for an edge
        list); they replace any positions in the file.

    Returns
    -------
    networkx.Graph
        Nodes with ``pos`` or ``x``/``y`` (and ``normal_load``, ``f_ext``)
        attributes, edges with ``k``/``kappa``/``rest_length`` where the
        file gives them, every value a float.

    Raises
    ------
    ConfigError
        A missing file, an unknown extension, a row or an element that
        cannot be read whole (naming the file and the line or the element),
        or no positions for some node.

    Examples
    --------
    >>> import tempfile, os
    >>> from slidernet.model.builders import from_graph
    >>> d = tempfile.mkdtemp()
    >>> with open(os.path.join(d, "net.edgelist"), "w") as f:
    ...     _ = f.write("0 1 k=2.0\\n1 2\\n")
    >>> G = read_graph(os.path.join(d, "net.edgelist"), positions=[0.0, 1.0, 2.0])
    >>> from_graph(G, Ntilde=1e-7).k.tolist()
    [2.0, 1.0]
    """
    p = Path(path)
    suffix = _suffix(p, "read_graph")
    if p.is_dir():
        raise ConfigError(f"The network file {str(p)!r} is a folder, not a file.")
    if not p.is_file():
        raise ConfigError(f"The network file {str(p)!r} does not exist.")
    try:
        return _read_graph(p, suffix, positions)
    except OSError as exc:  # no permission, ...: the reason in the system's words
        raise ConfigError(f"The network file {str(exc.filename or p)!r} cannot be read: "
                          f"{exc.strerror or exc}.") from None


def _read_graph(p: Path, suffix: str, positions: Any) -> nx.Graph:
    """:func:`read_graph` of a file that exists (the reading only)."""
    if suffix == ".graphml":
        G = _read_graphml(p)
        if positions is not None:
            _set_positions(G, list(G.nodes), positions, p)
        _check_graphml_attributes(G, p)
        return G
    if positions is not None:
        pos = _positions_array(positions)
        G = nx.Graph()
        G.add_nodes_from((v, {"pos": tuple(row)}) for v, row in enumerate(pos.tolist()))
    else:
        nodes = _nodes_file(p)
        if not nodes.is_file():
            raise ConfigError(
                f"The edge list {str(p)!r} has no positions: pass positions, or write them to "
                f"{str(nodes)!r} (CSV with header node,x[,y][,normal_load])."
            )
        G = _read_nodes_csv(nodes)
    if suffix == ".csv":
        _read_edges_csv(p, G)
    else:
        _read_edges_text(p, G)
    return G


# --------------------------------------------------------------------------
# GraphML
# --------------------------------------------------------------------------


def _read_graphml(p: Path) -> nx.Graph:
    """A GraphML file as an undirected graph, each spring once; node ids that are all integers as ints."""
    try:
        # A multigraph keeps what a Graph would merge: a spring given twice is refused, not summed or dropped.
        M = nx.read_graphml(p, force_multigraph=True)
    except (ParseError, nx.NetworkXError, ValueError, KeyError) as err:
        raise ConfigError(f"Cannot read the GraphML file {str(p)!r}: {err}") from err
    where = f"The GraphML file {str(p)!r}"
    # GraphML ids are strings; integer ids (as networkx writes them) read back as ints.
    try:
        label = {v: int(v) for v in M.nodes}
    except (TypeError, ValueError):
        label = {v: v for v in M.nodes}
    if len(set(label.values())) != len(label):
        label = {v: v for v in M.nodes}
    G = nx.Graph()
    G.add_nodes_from((label[v], data) for v, data in M.nodes(data=True))  # the file's order
    for a, b, data in M.edges(data=True):
        i, j = label[a], label[b]
        if i == j:
            raise ConfigError(f"{where}: the spring ({i!r}, {j!r}) joins node {i!r} to itself.")
        if G.has_edge(i, j):
            raise ConfigError(f"{where}: the spring ({i!r}, {j!r}) is listed twice (a parallel edge, or both "
                              f"directions of a directed graph); give each spring once.")
        G.add_edge(i, j, **data)
    return G


def _checked_attributes(data: dict[str, Any], known: tuple[str, ...], ignored: tuple[str, ...], what: str,
                        where: str) -> None:
    """Every attribute of a GraphML element as a float, in place; an unknown one refused."""
    for key in ignored:
        data.pop(key, None)
    for key, value in data.items():
        if key not in known:
            raise ConfigError(f"{where}: unknown attribute {key!r}; a {what} takes "
                              f"{', '.join(repr(k) for k in known)}.")
        if not (key == "pos" and isinstance(value, tuple)):
            data[key] = read_real(value, repr(key), where)


def _check_graphml_attributes(G: nx.Graph, p: Path) -> None:
    """Every node and edge attribute of a GraphML graph a number slidernet knows; a position on every node."""
    where = f"The GraphML file {str(p)!r}"
    with_y = next((v for v, data in G.nodes(data=True) if "y" in data), None)
    for v, data in G.nodes(data=True):
        if isinstance(data.get("pos"), tuple):  # set from the positions argument: they replace x and y
            for c in ("x", "y"):
                data.pop(c, None)
            _checked_attributes(data, ("pos", *NODE_ATTRIBUTES), (), "node", f"{where}: node {v!r}")
            continue
        _checked_attributes(data, NODE_ATTRIBUTES, _GRAPHML_IGNORED["node"], "node", f"{where}: node {v!r}")
        if "x" not in data:
            raise ConfigError(
                f"Node {v!r} of {str(p)!r} has no position: GraphML nodes need 'x' (and 'y') "
                f"attributes in l0, or pass positions."
            )
        if with_y is not None and "y" not in data:
            raise ConfigError(f"{where}: node {v!r} has 'x' but no 'y', while node {with_y!r} has both: every "
                              f"node of a 2D network needs both, of a 1D one 'x' alone.")
    for i, j, data in G.edges(data=True):
        _checked_attributes(data, SPRING_ATTRIBUTES, _GRAPHML_IGNORED["edge"], "spring",
                            f"{where}: edge ({i!r}, {j!r})")


def _positions_array(positions: Any) -> np.ndarray:
    try:
        pos = np.asarray(positions, dtype=float)
    except (TypeError, ValueError):
        raise param_error("positions", "read_graph", "an array of shape (N,) or (N, 2)", positions) from None
    if pos.ndim == 1:
        pos = pos[:, None]
    if pos.ndim != 2 or pos.shape[1] not in (1, 2) or pos.shape[0] < 1:
        raise param_error("positions", "read_graph", "an array of shape (N,) or (N, 2)",
                          f"an array of shape {np.shape(positions)}")
    return pos


def _set_positions(G: nx.Graph, nodes: list, positions: Any, p: Path) -> None:
    pos = _positions_array(positions)
    if pos.shape[0] != len(nodes):
        raise param_error("positions", "read_graph", f"one position per node of {str(p)!r} ({len(nodes)})",
                          f"{pos.shape[0]} positions")
    for v, row in zip(nodes, pos.tolist(), strict=True):
        G.nodes[v]["pos"] = tuple(row)


# --------------------------------------------------------------------------
# Edge lists and node files
# --------------------------------------------------------------------------


def _int(text: str, what: str, where: str) -> int:
    """A node id: the text of a whole number, digits only (no '1_0', no '1.0')."""
    digits = text.strip() if isinstance(text, str) else ""
    if digits.lstrip("+-").isdigit() and digits.isascii():
        return int(digits)
    raise ConfigError(f"{where}: {what} must be an integer node id. Got {text!r} instead.")


def _text(path: Path) -> io.StringIO:
    """A network's text file (edge list, nodes file), read as UTF-8 (a byte-order mark is skipped), as a stream.

    Not the locale's encoding: a file then reads the same on every machine, as the TOML file that names it.
    """
    data = path.read_bytes()
    try:
        return io.StringIO(data.decode("utf-8-sig"), newline="")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise ConfigError(f"The network file {str(path)!r} is not UTF-8 text: byte 0x{data[exc.start]:02x} on "
                          f"line {line} cannot be decoded. Save it as UTF-8.") from None


def _csv_rows(path: Path, header_ok: Any, wanted: str) -> Iterator[tuple[list[str], dict[str, str], str]]:
    """(columns, row by column, where) for every row of a CSV file with a header, blank lines skipped.

    ``header_ok(columns)`` says whether the header is one the file may have (``wanted`` says which); a
    row with another number of fields than the header is refused, naming the file and the line.
    """
    with _text(path) as f:
        reader = csv.reader(f)
        header = next(reader, [])
        columns = [c.strip() for c in header]
        if not header_ok(columns):
            raise ConfigError(f"The {wanted}. Got {columns} instead.")
        for fields in reader:
            if not fields:
                continue
            where = f"{path}, line {reader.line_num}"
            if len(fields) != len(columns):
                raise ConfigError(f"{where}: {len(fields)} fields; the header {','.join(columns)} has "
                                  f"{len(columns)}.")
            yield columns, dict(zip(columns, fields, strict=True)), where


def _read_nodes_csv(path: Path) -> nx.Graph:
    G = nx.Graph()
    allowed = {"node", "x", "y", "normal_load"}
    rows = _csv_rows(path, lambda c: "node" in c and "x" in c and set(c) <= allowed,
                     f"node file {str(path)!r} needs the header node,x[,y][,normal_load]")
    for columns, row, where in rows:
        v = _int(row["node"], "'node'", where)
        if v in G:
            raise ConfigError(f"{where}: node {v} is listed twice.")
        pos = tuple(read_real(row[c], repr(c), where) for c in ("x", "y") if c in columns)
        data: dict[str, Any] = {"pos": pos}
        if row.get("normal_load", "").strip():  # empty: the default
            data["normal_load"] = read_real(row["normal_load"], "'normal_load'", where)
        G.add_node(v, **data)
    return G


def _add_spring(G: nx.Graph, i: int, j: int, data: dict[str, float], where: str) -> None:
    for v in (i, j):
        if v not in G:
            raise ConfigError(f"{where}: node {v} has no position.")
    if i == j:
        raise ConfigError(f"{where}: the spring ({i}, {j}) joins node {i} to itself.")
    if G.has_edge(i, j):
        raise ConfigError(f"{where}: the spring ({i}, {j}) is listed twice.")
    G.add_edge(i, j, **data)


def _spring_data(items: Mapping[Any, Any], where: str) -> dict[str, float]:
    data = {}
    for key, value in items.items():
        if key not in SPRING_ATTRIBUTES:
            raise ConfigError(
                f"{where}: unknown spring attribute {key!r}; expected 'k', 'kappa' or 'rest_length'."
            )
        data[key] = read_real(value, repr(key), where)
    return data


def _read_edges_text(path: Path, G: nx.Graph) -> None:
    with _text(path) as f:
        for number, raw in enumerate(f, start=1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            where = f"{path}, line {number}"
            tokens = line.split(None, 2)
            if len(tokens) < 2:
                raise ConfigError(f"{where}: expected 'i j [key=value ...]'. Got {line!r} instead.")
            rest = tokens[2] if len(tokens) == 3 else ""
            if rest.startswith("{"):
                try:
                    items = ast.literal_eval(rest)
                except (ValueError, SyntaxError):
                    items = None
                if not isinstance(items, dict):
                    raise ConfigError(f"{where}: cannot read the spring attributes {rest!r}.")
            else:
                items = {}
                for tok in rest.split():
                    key, eq, value = tok.partition("=")
                    if not eq:
                        raise ConfigError(f"{where}: expected key=value after 'i j'. Got {tok!r} instead.")
                    if key in items:
                        raise ConfigError(f"{where}: the spring attribute {key!r} is given twice.")
                    items[key] = value
            i = _int(tokens[0], "i", where)
            j = _int(tokens[1], "j", where)
            _add_spring(G, i, j, _spring_data(items, where), where)


def _read_edges_csv(path: Path, G: nx.Graph) -> None:
    def ends_of(columns: list[str]) -> tuple[str, str] | None:
        return next((pair for pair in (("i", "j"), ("source", "target")) if set(pair) <= set(columns)), None)

    rows = _csv_rows(path, lambda c: ends_of(c) is not None and set(c) - set(ends_of(c)) <= set(SPRING_ATTRIBUTES),
                     f"edge list {str(path)!r} needs the header i,j (or source,target) [,k][,kappa][,rest_length]")
    for columns, row, where in rows:
        ends = ends_of(columns)
        data = {c: v for c, v in row.items() if c not in ends and v.strip()}  # an empty field: the default
        _add_spring(G, _int(row[ends[0]], ends[0], where), _int(row[ends[1]], ends[1], where),
                    _spring_data(data, where), where)


# --------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------


def write_graph(net: Network, path: str | PathLike[str]) -> list[Path]:
    """Write a network to a file that :func:`read_graph` reads back exactly.

    ``.graphml`` stores positions as node attributes ``x`` (and ``y``);
    edge lists (``.edgelist``, ``.txt``: ``i j k=.. kappa=.. rest_length=..``;
    ``.csv``: header ``i,j,k,kappa,rest_length``) also write the companion
    ``<stem>.nodes.csv`` (``node,x[,y],normal_load``). Floats are written with
    ``repr``, so reading back gives the same arrays bit for bit. Node ids are
    the indices 0..N-1.

    Parameters
    ----------
    net : Network
        The network to write.
    path : str or path-like
        Destination; its extension chooses the format.

    Returns
    -------
    list of pathlib.Path
        The files written.

    Examples
    --------
    >>> import tempfile, os
    >>> from slidernet.model.builders import from_graph, square
    >>> net = square((2, 2), Ntilde=1e-7, k=[1.0, 2.0, 3.0, 4.0])
    >>> path = os.path.join(tempfile.mkdtemp(), "net.graphml")
    >>> back = from_graph(read_graph(write_graph(net, path)[0]), Ntilde=1e-7)
    >>> back.k.tolist(), bool((back.positions == net.positions).all())
    ([1.0, 2.0, 3.0, 4.0], True)
    """
    p = Path(path)
    suffix = _suffix(p, "write_graph")
    axes = ("x", "y")[: net.dim]
    if suffix == ".graphml":
        G = net.to_networkx()
        for _, data in G.nodes(data=True):
            data.update(zip(axes, data.pop("pos"), strict=True))
            if "f_ext" in data:  # GraphML attributes are scalars
                data.update(zip(("f_ext_x", "f_ext_y"), data.pop("f_ext"), strict=False))
        nx.write_graphml(G, p)
        return [p]
    if net.f_ext.any():
        # Refused rather than dropped: the edge-list formats have no column for it.
        raise ConfigError(f"{str(p)!r}: an edge list cannot store the network's external forces f_ext; "
                          "write a '.graphml' file instead.")
    nodes = _nodes_file(p)
    with nodes.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["node", *axes, "normal_load"])
        # tolist() gives Python floats, whose str is the shortest exact repr.
        for v, (pos, load) in enumerate(zip(net.positions.tolist(), net.normal_load.tolist(), strict=True)):
            w.writerow([v, *pos, load])
    cols = zip(net.edges.tolist(), net.k.tolist(), net.kappa.tolist(), net.rest_length.tolist(), strict=True)
    with p.open("w", newline="", encoding="utf-8") as f:
        if suffix == ".csv":
            w = csv.writer(f)
            w.writerow(["i", "j", "k", "kappa", "rest_length"])
            w.writerows([i, j, k, kappa, L] for (i, j), k, kappa, L in cols)
        else:
            f.write("# i j k=.. kappa=.. rest_length=..  (positions in " + nodes.name + ")\n")
            f.writelines(f"{i} {j} k={k!r} kappa={kappa!r} rest_length={L!r}\n" for (i, j), k, kappa, L in cols)
    return [p, nodes]
