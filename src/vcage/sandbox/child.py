"""The sandbox's child process: run one checked program against a recording facade, print JSON.

Started by :mod:`vcage.sandbox.runner` as ``python -I -S child.py`` with an empty environment, in
an empty temporary directory, in a session of its own. It imports the standard library only (it
never sees vcage, the simulator or the parent's objects) and is the one module of the package that
compiles and executes text as code. In order, it:

1. reads the request (program, skill API, scene snapshot, limits) as JSON from stdin;
2. lowers its own limits: CPU seconds, address space, file size 0, no new processes, no new files;
3. compiles the program, then arms an audit hook that refuses every audited event (opening files,
   sockets, imports, fork and exec, ``compile``, frame access) except the one ``exec`` of the program;
4. runs the program with a builtins table of a few safe functions and the facade, whose skill
   functions only *record* their calls (the parent validates and executes them);
5. prints one JSON object (``{"ok": true, "calls": [...], "log": [...]}`` or
   ``{"ok": false, "error_type": ..., "error": ..., "line": ...}``) and ends with ``os._exit``.
"""

import json
import os
import resource
import sys

MAX_RANGE = 100_000  # the longest range a program may build
MAX_LOG = 50  # lines of print output kept
MAX_TEXT = 200  # characters of a string argument or a log line


class Refused(Exception):  # noqa: N818 - the name says what happened
    """A facade rule the program broke (too many calls, unknown argument, bad value type)."""


def limit(which, soft, hard=None):
    try:  # noqa: SIM105 - the child imports as little as it can (no contextlib)
        resource.setrlimit(which, (soft, soft if hard is None else hard))
    except (ValueError, OSError):  # e.g. above the current hard limit: keep the tighter one
        pass


def lower_limits(limits):
    cpu = int(limits["cpu_seconds"])
    limit(resource.RLIMIT_CPU, cpu, cpu + 1)
    limit(resource.RLIMIT_AS, int(limits["memory_bytes"]))
    limit(resource.RLIMIT_FSIZE, 0)
    limit(resource.RLIMIT_CORE, 0)
    if hasattr(resource, "RLIMIT_NPROC"):
        limit(resource.RLIMIT_NPROC, 0)
    limit(resource.RLIMIT_NOFILE, 3)


def plain(value, depth=0):
    """``value`` as JSON data (lists for tuples), or Refused for anything else."""
    if value is None or isinstance(value, (bool, int, float)):
        return value
    if isinstance(value, str):
        if len(value) > MAX_TEXT:
            raise Refused(f"a string argument is longer than {MAX_TEXT} characters")
        return value
    if isinstance(value, (list, tuple)) and depth < 2:
        if len(value) > 16:
            raise Refused("a list argument has more than 16 items")
        return [plain(v, depth + 1) for v in value]
    raise Refused(f"a skill argument must be a number, string, bool, None or a short list, "
                  f"not {type(value).__name__}")


def facade(api, scene, calls, max_calls, log):
    """The names a program sees: one recording function per skill, scene queries, safe builtins."""

    def skill_function(name, params, required):
        def record(*args, **kwargs):
            if len(args) > len(params):
                raise Refused(f"{name}() takes at most {len(params)} positional arguments")
            bound = dict(zip(params, args, strict=False))
            for key, value in kwargs.items():
                if key not in params:
                    raise Refused(f"{name}() has no argument {key!r}; it takes {params}")
                if key in bound:
                    raise Refused(f"{name}() got argument {key!r} twice")
                bound[key] = value
            missing = [p for p in required if p not in bound]
            if missing:
                raise Refused(f"{name}() needs argument(s) {missing}")
            if len(calls) >= max_calls:
                raise Refused(f"more than {max_calls} skill calls")
            calls.append({"skill": name, "args": {k: plain(v) for k, v in bound.items()}})

        return record

    poses = {name: tuple(float(v) for v in pose) for name, pose in scene["objects"].items()}

    def pose(name):
        """(x, y, z, yaw) of object ``name`` now."""
        if name not in poses:
            raise Refused(f"no object {name!r}; objects: {sorted(poses)}")
        return poses[name]

    def position(name):
        return pose(name)[:3]

    def objects():
        return sorted(poses)

    def bounded_range(*args):
        r = range(*args)
        if len(r) > MAX_RANGE:
            raise Refused(f"range of {len(r)} items, more than {MAX_RANGE}")
        return r

    def captured_print(*args):
        if len(log) < MAX_LOG:
            log.append(" ".join(str(a) for a in args)[:MAX_TEXT])

    import builtins

    safe = {n: getattr(builtins, n) for n in ("abs", "min", "max", "round", "len", "float", "int", "bool",
                                              "str", "list", "tuple", "dict", "enumerate", "zip", "sum",
                                              "sorted", "reversed", "any", "all")}
    safe.update(range=bounded_range, print=captured_print)
    names = {spec["name"]: skill_function(spec["name"], tuple(spec["params"]), tuple(spec["required"]))
             for spec in api}
    names.update(pose=pose, position=position, objects=objects,
                 TABLE_X=tuple(scene["table_x"]), TABLE_Y=tuple(scene["table_y"]),
                 TABLE_Z=float(scene["table_z"]))
    return {"__builtins__": safe, **names}


def arm():
    """Refuse every audited event from now on, except the one ``exec`` of the program."""
    budget = [1]

    def hook(event, args):
        if event == "exec" and budget[0] > 0:
            budget[0] -= 1
            return
        raise PermissionError(f"sandbox: {event} is not allowed")

    sys.addaudithook(hook)


def user_line(exc):
    """The line of the program where ``exc`` was raised (its traceback's second entry)."""
    tb = exc.__traceback__
    tb = tb.tb_next if tb is not None else None
    return tb.tb_lineno if tb is not None else None


def main():
    write, flush, _exit = sys.stdout.write, sys.stdout.flush, os._exit
    request = json.loads(sys.stdin.read())
    sys.stdin.close()
    lower_limits(request["limits"])
    calls: list = []
    log: list = []
    env = facade(request["api"], request["scene"], calls, int(request["limits"]["max_calls"]), log)
    try:
        code = compile(request["code"], "<subtask>", "exec", dont_inherit=True)
    except BaseException as exc:  # the parent checked it; a failure here is reported, not raised
        out = {"ok": False, "error_type": type(exc).__name__, "error": str(exc)[:500], "line": None}
    else:
        arm()
        try:
            exec(code, env)
            out = {"ok": True, "calls": calls, "log": log}
        except BaseException as exc:
            out = {"ok": False, "error_type": type(exc).__name__, "error": str(exc)[:500],
                   "line": user_line(exc)}
    try:
        text = json.dumps(out)
    except BaseException as exc:  # e.g. an integer too long to print
        text = json.dumps({"ok": False, "error_type": type(exc).__name__, "error": str(exc)[:500],
                           "line": None})
    write(text + "\n")
    flush()
    _exit(0)


if __name__ == "__main__":
    main()
