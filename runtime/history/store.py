"""The history store: one SQL database (a SQLite file, or PostgreSQL by a URL), one code path.

Through SQLAlchemy 2 Core (one library for both back ends; the PostgreSQL driver is psycopg
3, the optional extra ``volerr[postgresql]``).  Every value is sent as a bound parameter: a
machine id, a file name or a parameter name is only ever data, never SQL text.

Schema (version :data:`SCHEMA_VERSION`, tables prefixed ``volerr_`` so that a shop's server
database can hold them beside its own):

* ``volerr_schema_version(version)``: one row.  A store of a newer (unknown) version is
  refused; an older one would be migrated here (there is none yet).
* ``volerr_entries``: one row per result: ``machine``, ``date`` (YYYY-MM-DD), ``kind``
  (calibration | check), ``layout``, ``sha256`` of the result file (unique), ``source`` (its
  file name), ``reference_sha256`` (a check's calibration), ``verdict``, ``covariance``
  (JSON text or NULL), ``files`` (JSON text: the instrument files' SHA-256), ``document``
  (the result's JSON text as read), ``added_at`` (UTC, ISO 8601).
* ``volerr_values``: ``(entry_id, parameter)`` -> ``value``, ``std``, ``unit``, ``status``,
  ``change`` (double precision; NULL for a parameter a check names without a number).

Rules:

* The same result (same SHA-256) added again to the same machine on the same date is a no
  operation (re-running a script is safe); on another machine or date it is refused: one
  result is one machine at one time.
* Writes are transactions.  SQLite: ``BEGIN IMMEDIATE`` (the writer takes the lock before it
  reads, so two processes adding at once serialise instead of failing on upgrade), waiting
  up to ``wait_s`` for the lock (SQLite's busy timeout); PostgreSQL: a transaction-level
  advisory lock (``pg_advisory_xact_lock``) with ``lock_timeout``.  A lock not obtained in
  time: :class:`InputError` ("locked"), nothing written.
* A file that is not an SQLite database, or an SQLite database with tables of its own but
  none of volerr's, is refused before anything is written (never a foreign file changed).
* A new SQLite history is never half made and never removed: the first ``add``
  (:func:`add_to_new_file`) writes schema and entries into a file in a staging folder of its
  own beside it and links it into place only after its transaction committed (``os.link``
  fails when the name exists, so of two processes creating the same history at once one
  wins and the other adds to the winner's file).  A failing command removes only that
  staging folder of its own, never the history.
* Schema creation tolerates a racing creator (``CREATE TABLE IF NOT EXISTS`` under the
  writer's lock, retried on "already exists"); ``sha256`` is unique, and a transaction that
  breaks it (a writer that did not take the lock) is rolled back and raised as
  :class:`Conflict` so that the caller re-runs it against what is stored.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import tempfile
from pathlib import Path

from ..errors import InputError, require
from .results import CHECK, Entry, Value, with_reference_parts

SCHEMA_VERSION = 1
#: an arbitrary constant key of the PostgreSQL advisory lock that serialises writers
_PG_LOCK_KEY = 370_003_001
#: attempts at creating the schema when a racing creator makes it at the same time
_SCHEMA_ATTEMPTS = 3


class Conflict(Exception):
    """A write broke a unique constraint (another writer stored the same result in between):
    the transaction was rolled back, nothing written; run it again."""


def _tables(sa):
    md = sa.MetaData()
    version = sa.Table("volerr_schema_version", md,
                       sa.Column("version", sa.Integer, nullable=False))
    entries = sa.Table(
        "volerr_entries", md,
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("machine", sa.String(64), nullable=False, index=True),
        sa.Column("date", sa.String(10), nullable=False),
        sa.Column("kind", sa.String(16), nullable=False),
        sa.Column("layout", sa.String(200), nullable=False),
        sa.Column("sha256", sa.String(64), nullable=False, unique=True),
        sa.Column("source", sa.String(1000), nullable=False),
        sa.Column("reference_sha256", sa.String(64)),
        sa.Column("verdict", sa.String(16)),
        sa.Column("covariance", sa.Text),
        sa.Column("files", sa.Text, nullable=False),
        sa.Column("document", sa.Text, nullable=False),
        sa.Column("added_at", sa.String(32), nullable=False))
    values = sa.Table(
        "volerr_values", md,
        sa.Column("entry_id", sa.Integer, sa.ForeignKey("volerr_entries.id"),
                  primary_key=True),
        sa.Column("parameter", sa.String(100), primary_key=True),
        sa.Column("value", sa.Double),
        sa.Column("std", sa.Double),
        sa.Column("unit", sa.String(32), nullable=False),
        sa.Column("status", sa.String(16), nullable=False),
        sa.Column("change", sa.Double))
    return md, version, entries, values


def _sqlalchemy():
    try:
        import sqlalchemy as sa
    except ImportError:
        raise InputError("volerr history needs SQLAlchemy 2: pip install 'sqlalchemy>=2'") \
            from None
    return sa


class Store:
    """A history database (module docstring).  ``db``: a file path (SQLite; created by the
    first :meth:`add`) or a ``postgresql://`` URL; ``wait_s``: how long a writer waits for
    another one's lock, s; ``create``: make the schema when the database has none."""

    def __init__(self, db: str, wait_s: float = 10.0, create: bool = False,
                 shown: str | None = None):
        self.sa = sa = _sqlalchemy()
        self.db = str(db)
        self.wait_s = float(wait_s)
        self.md, self.t_version, self.t_entries, self.t_values = _tables(sa)
        self.postgres = self.db.startswith(("postgresql://", "postgresql+psycopg://",
                                            "postgres://"))
        self.shown = shown or self._shown()
        self.engine = self._pg_engine() if self.postgres else self._sqlite_engine(create)
        self._open(create)

    # -- connection ----------------------------------------------------------------------
    def _shown(self) -> str:
        if not self.postgres:
            return self.db
        try:
            return self.sa.engine.make_url(self._pg_url()).render_as_string(hide_password=True)
        except Exception:
            return "postgresql://..."

    def _pg_url(self) -> str:
        rest = self.db.split("://", 1)[1]
        return "postgresql+psycopg://" + rest

    def _pg_engine(self):
        try:
            import psycopg  # noqa: F401
        except ImportError:
            raise InputError("a postgresql:// history needs psycopg 3: pip install "
                             "'volerr[postgresql]'") from None
        try:
            return self.sa.create_engine(self._pg_url(), poolclass=self.sa.pool.NullPool,
                                         connect_args={"connect_timeout": 10})
        except Exception as exc:
            raise InputError(f"{self.shown}: not a PostgreSQL URL ({_first_line(exc)})") \
                from None

    def _sqlite_engine(self, create: bool):
        sa = self.sa
        p = Path(self.db)
        require(not p.is_dir(), f"--db {self.db}: a folder, not a history file")
        if not p.exists():
            require(create, f"--db {self.db}: no such history (add results first)")
            require(p.parent.is_dir() if str(p.parent) else True,
                    f"--db {self.db}: folder {p.parent} does not exist")
        else:
            with open(p, "rb") as fh:
                head = fh.read(16)
            require(not head or head == b"SQLite format 3\x00",
                    f"--db {self.db}: not a volerr history (not an SQLite database)")
        engine = sa.create_engine(f"sqlite:///{p}", poolclass=sa.pool.NullPool,
                                  connect_args={"timeout": self.wait_s})

        @sa.event.listens_for(engine, "connect")
        def _connect(dbapi_conn, _record):
            dbapi_conn.isolation_level = None       # transactions begun by _begin below

        @sa.event.listens_for(engine, "begin")
        def _begin(conn):
            conn.exec_driver_sql("BEGIN IMMEDIATE" if conn.info.get("write") else "BEGIN")

        return engine

    def _connect(self, write: bool):
        """A connection in a transaction (``with store._connect(True) as conn``)."""
        sa = self.sa
        try:
            conn = self.engine.connect()
        except sa.exc.OperationalError as exc:
            raise InputError(f"{self.shown}: cannot connect ({_first_line(exc.orig)})") \
                from None
        conn.info["write"] = write
        return conn

    # -- schema --------------------------------------------------------------------------
    def _open(self, create: bool) -> None:
        """Check the schema (made when ``create`` and there is none), retried when a racing
        creator made it between our look and our CREATE ("already exists")."""
        for attempt in range(_SCHEMA_ATTEMPTS):
            try:
                return self._open_once(create)
            except Conflict:
                if attempt == _SCHEMA_ATTEMPTS - 1:
                    raise InputError(f"--db {self.shown}: another process kept creating the "
                                     f"history at the same time; nothing written, try "
                                     f"again") from None

    def _open_once(self, create: bool) -> None:
        with self._guard():
            with self._connect(create) as conn, conn.begin():
                if self.postgres and create:
                    self._pg_lock(conn)
                names = set(self.sa.inspect(conn).get_table_names())
                if "volerr_schema_version" not in names:
                    require(not (names and not self.postgres),
                            f"--db {self.shown}: not a volerr history (an SQLite database "
                            f"with other tables: {', '.join(sorted(names)[:5])})")
                    require(create, f"--db {self.shown}: no volerr history there (add "
                                    f"results first)")
                    self.md.create_all(conn, checkfirst=True)
                    conn.execute(self.t_version.insert().values(version=SCHEMA_VERSION))
                    return
                rows = conn.execute(self.sa.select(self.t_version.c.version)).all()
                require(len(rows) == 1, f"--db {self.shown}: not a volerr history (a broken "
                                        f"schema_version table)")
                v = rows[0][0]
                require(v <= SCHEMA_VERSION,
                        f"--db {self.shown}: written by a newer volerr (schema version {v}; "
                        f"this one reads up to {SCHEMA_VERSION})")
                require(v == SCHEMA_VERSION, f"--db {self.shown}: schema version {v} is "
                                             f"unknown")

    def _pg_lock(self, conn) -> None:
        ms = max(1, int(round(self.wait_s * 1000)))
        conn.exec_driver_sql(f"SET LOCAL lock_timeout = {ms}")
        conn.execute(self.sa.text("SELECT pg_advisory_xact_lock(:k)"), {"k": _PG_LOCK_KEY})

    def _guard(self):
        return _Guard(self)

    # -- reading -------------------------------------------------------------------------
    def entries(self, machine: str) -> list:
        """Every entry of ``machine``, in date order (same date: the order they were added)."""
        sa, e, v = self.sa, self.t_entries, self.t_values
        with self._guard(), self._connect(False) as conn, conn.begin():
            rows = conn.execute(sa.select(e).where(e.c.machine == machine)
                                .order_by(e.c.date, e.c.id)).mappings().all()
            ids = [r["id"] for r in rows]
            vals: dict = {i: {} for i in ids}
            if ids:
                for r in conn.execute(sa.select(v).where(v.c.entry_id.in_(ids))
                                      .order_by(v.c.entry_id, v.c.parameter)).mappings():
                    vals[r["entry_id"]][r["parameter"]] = Value(
                        r["value"], r["std"], r["unit"], r["status"], r["change"])
        return [_entry(r, vals[r["id"]]) for r in rows]

    def machines(self) -> list:
        sa, e = self.sa, self.t_entries
        with self._guard(), self._connect(False) as conn, conn.begin():
            return [r[0] for r in conn.execute(sa.select(e.c.machine).distinct()
                                               .order_by(e.c.machine))]

    # -- writing -------------------------------------------------------------------------
    def add(self, machine: str, entries: list, prepare) -> list:
        """Add ``entries`` (:class:`Entry`, dated) to ``machine`` in ONE transaction: all or
        none.  ``prepare(entry, stored)`` is called inside the transaction with the entries
        already stored (date order) and may raise :class:`InputError` (a check's reference
        applied there, so a reference added by another process at the same time is seen).
        Returns one ``(entry, "added" | "already stored")`` per entry."""
        sa, e = self.sa, self.t_entries
        out = []
        with self._guard(), self._connect(True) as conn, conn.begin():
            if self.postgres:
                self._pg_lock(conn)
            for entry in entries:
                old = conn.execute(sa.select(e.c.machine, e.c.date, e.c.source)
                                   .where(e.c.sha256 == entry.sha256)).first()
                if old is not None:
                    require(old.machine == machine and old.date == entry.date,
                            f"{entry.source}: this result is in the history already, as "
                            f"{old.source} of machine {old.machine!r} on {old.date}; one "
                            f"result is one machine at one time")
                    out.append((entry, "already stored"))
                    continue
                prepare(entry, self._stored(conn, machine))
                self._insert(conn, machine, entry)
                out.append((entry, "added"))
        return out

    def _stored(self, conn, machine: str) -> list:
        sa, e, v = self.sa, self.t_entries, self.t_values
        rows = conn.execute(sa.select(e).where(e.c.machine == machine)
                            .order_by(e.c.date, e.c.id)).mappings().all()
        out = []
        for r in rows:
            vals = {x["parameter"]: Value(x["value"], x["std"], x["unit"], x["status"],
                                          x["change"])
                    for x in conn.execute(sa.select(v).where(v.c.entry_id == r["id"]))
                    .mappings()}
            out.append(_entry(r, vals))
        return out

    def _insert(self, conn, machine: str, entry: Entry) -> None:
        e, v = self.t_entries, self.t_values
        now = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
        res = conn.execute(e.insert().values(
            machine=machine, date=entry.date, kind=entry.kind, layout=entry.layout,
            sha256=entry.sha256, source=entry.source, reference_sha256=entry.reference_sha256,
            verdict=entry.verdict, added_at=now, document=entry.document,
            covariance=json.dumps(entry.covariance) if entry.covariance else None,
            files=json.dumps(entry.files)))
        eid = res.inserted_primary_key[0]
        rows = [{"entry_id": eid, "parameter": n, "value": x.value, "std": x.std,
                 "unit": x.unit, "status": x.status, "change": x.change}
                for n, x in sorted(entry.values.items())]
        if rows:
            conn.execute(v.insert(), rows)


def add_to_new_file(path, wait_s: float, work):
    """Create the SQLite history ``path`` (which does not exist) with what ``work(store)``
    writes into it: ``work`` runs on a new file in a staging folder of this process beside
    ``path`` (named by :func:`volerr.fileio.staging_prefix`, so that one left by a killed
    process is removed by the next run, :func:`volerr.fileio.remove_stale_staging`); the
    file is linked to ``path`` only after ``work`` committed.  Returns ``(True, work's
    value)``, or ``(False, None)`` when another process created ``path`` first (then nothing
    of ours is left: add to that file instead).  On any failure the staging folder is
    removed and ``path`` never appears; nothing else is ever removed."""
    import shutil

    from ..fileio import remove_stale_staging, staging_prefix

    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    require(folder.is_dir(), f"--db {path}: folder {folder} does not exist")
    remove_stale_staging(folder)
    try:
        stage = Path(tempfile.mkdtemp(prefix=staging_prefix(), dir=folder))
    except OSError as exc:
        raise InputError(f"--db {path}: cannot create a file in {folder} "
                         f"({exc.strerror or exc})") from None
    try:
        store = Store(str(stage / path.name), wait_s=wait_s, create=True, shown=str(path))
        value = work(store)
        store.engine.dispose()
        if not _publish(stage / path.name, path):
            return False, None
        return True, value
    finally:
        shutil.rmtree(stage, ignore_errors=True)    # ours alone: made in this call


def _publish(tmp: Path, path: Path) -> bool:
    """Give the committed file ``tmp`` the name ``path`` unless that name exists (atomic:
    a hard link; Windows: a rename, which refuses an existing name).  False: it exists."""
    try:
        if os.name == "nt":
            os.rename(tmp, path)
        else:
            os.link(tmp, path)
    except FileExistsError:
        return False
    except OSError as exc:
        raise InputError(f"--db {path}: cannot create it ({exc.strerror or exc}; a folder "
                         f"without hard links? create the history on a local disk)") from None
    return True


def _entry(r, values: dict) -> Entry:
    if r["kind"] == CHECK:      # the reference's part of each std, from the stored document
        values = with_reference_parts(values, json.loads(r["document"]))
    return Entry(r["kind"], r["layout"], values, r["sha256"], r["source"], r["document"],
                 date=r["date"], verdict=r["verdict"],
                 covariance=json.loads(r["covariance"]) if r["covariance"] else None,
                 files=json.loads(r["files"]), reference_sha256=r["reference_sha256"])


def _first_line(exc) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


class _Guard:
    """Database errors as one line: a lock not obtained in time, a corrupt file, a server
    that refuses; :class:`InputError` passes through."""

    def __init__(self, store: Store):
        self.store = store

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc is None or isinstance(exc, InputError):
            return False
        sa = self.store.sa
        if not isinstance(exc, sa.exc.SQLAlchemyError):
            return False
        orig = getattr(exc, "orig", exc)
        text = _first_line(orig)
        where = f"--db {self.store.shown}"
        if "locked" in text or "lock timeout" in text or "LockNotAvailable" in \
                type(orig).__name__:
            raise InputError(f"{where}: locked by another process (waited "
                             f"{self.store.wait_s:g} s, nothing written); try again") from None
        if "not a database" in text or "malformed" in text:
            raise InputError(f"{where}: not a volerr history (a corrupt SQLite file: "
                             f"{text})") from None
        if isinstance(exc, sa.exc.IntegrityError) or "already exists" in text:
            raise Conflict(text) from None
        raise InputError(f"{where}: {text}") from None
