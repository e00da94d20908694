"""Which code made a policy's numbers: a SHA-256 of its code, with davis-ag's version and commit.

A results row names its policy by the spec it was given (``my_policy.py:toward_target``), and two
files may hold rows of one name made by different code. Each row therefore carries a digest of
what played: a trained model's zip (or, for a model given in memory, its parameters), a policy's
source file (the file of its function or class: a ``file.py:attr`` spec, an installed module, a
callable handed to :func:`davis_ag.benchmark.evaluate`), for a baseline the davis-ag file that
defines it. With the package version and commit beside it, a number can be traced to its code;
``davis-ag compare`` shows the digest's first :data:`SHORT` characters on every row.
"""

from __future__ import annotations

import hashlib
import inspect
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from davis_ag.benchmark.results import CodeDigest

if TYPE_CHECKING:
    from davis_ag.benchmark.policies import Policy

#: Characters of the digest a leaderboard shows (32 bits: a chance collision needs ~65,000 rows).
SHORT = 8
#: Bytes read at a time while hashing a file.
_CHUNK = 1 << 20


def file_sha256(path: Path) -> str:
    """The SHA-256 of a file's bytes, hex."""
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        while chunk := handle.read(_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def _parameters_sha256(model: Any) -> str:
    """The SHA-256 of a model's parameters (names, shapes, values) in a fixed order."""
    digest = hashlib.sha256()
    for name, tensor in sorted(model.policy.state_dict().items()):
        values = tensor.detach().cpu().contiguous().numpy()
        digest.update(f"{name}{values.dtype}{values.shape}".encode())
        digest.update(values.tobytes())
    return digest.hexdigest()


def _source_file(policy: Policy) -> Path | None:
    """The file of the code that acts: a wrapped function's, else the policy's class's."""
    thing = getattr(policy, "function", None) or type(policy)
    thing = thing if inspect.isfunction(thing) or inspect.isclass(thing) else type(thing)
    try:
        found = inspect.getsourcefile(thing)
    except TypeError:  # built-in: no file to hash
        return None
    return Path(found) if found and Path(found).is_file() else None


def code_digest(policy: Policy) -> CodeDigest:
    """The digest of the code a policy plays with (see the module docstring).

    Args:
        policy: A :class:`davis_ag.benchmark.policies.Policy` (a ``ModelPolicy`` hashes its model).

    Returns:
        The digest, what it was taken of (``model``: the zip; ``parameters``: a model given in
        memory; ``source``: the file of its code; ``name``: code with no file, its qualified name)
        and that file's name, davis-ag's version and commit.
    """
    from davis_ag import __version__
    from davis_ag.provenance import source_revision

    path: Path | None = getattr(policy, "path", None)
    model = getattr(policy, "model", None)
    of: Literal["model", "parameters", "source", "name"]
    name: str | None
    if path is not None and path.is_file():
        sha, of, name = file_sha256(path), "model", path.name
    elif model is not None and hasattr(model, "policy"):
        sha, of, name = _parameters_sha256(model), "parameters", None
    elif (source := _source_file(policy)) is not None:
        sha, of, name = file_sha256(source), "source", source.name
    else:
        thing = getattr(policy, "function", None) or type(policy)
        sha, of, name = hashlib.sha256(getattr(thing, "__qualname__", repr(thing)).encode()).hexdigest(), "name", None
    return CodeDigest(sha256=sha, of=of, file=name, package=__version__, commit=source_revision())


def is_davis_ag_code(digest: CodeDigest | None) -> bool:
    """Whether a row's digest is of a file of this davis-ag as installed (a baseline of ours), byte
    for byte: a leaderboard needs no one's code to re-run such a row (the replay checks it)."""
    if digest is None or digest.of != "source" or not digest.file:
        return False
    package = Path(__file__).resolve().parents[1]
    return any(file_sha256(path) == digest.sha256 for path in package.rglob(digest.file))
