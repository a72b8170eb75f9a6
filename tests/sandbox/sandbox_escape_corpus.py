"""Known ways out of a Python sandbox, each a program a model could write; all must be blocked.

Shared by ``test_sandbox_escapes.py`` and ``benchmarks/sandbox.py``. A program is *blocked* when the
sandbox refuses or stops it (any status but ``ok``) or, for programs that run, when the parent's
argument check refuses one of the calls it recorded (NaN, off the table, unknown objects).
"""

from __future__ import annotations

from vcage.errors import SubtaskError
from vcage.sandbox import RunResult, SceneSnapshot, SkillSignature
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.calls import api, check_call

WALK = "w = [c for c in ().__class__.__bases__[0].__subclasses__() if c.__name__ == '_wrap_close'][0]\n"
ESCAPES: dict[str, str] = {
    "subclasses walk": "().__class__.__bases__[0].__subclasses__()\n",
    "subclasses to os.system": WALK + "w.__init__.__globals__['system']('touch pwned')\n",
    "function __globals__": "f = print\ng = f.__globals__\n",
    "generator gi_frame": "g = [x for x in range(3)]\nh = (x for x in g)\nh.gi_frame.f_globals\n",
    "traceback tb_frame": "try:\n    1 / 0\nexcept Exception as e:\n    e.__traceback__.tb_frame\n",
    "format string traversal": "s = '{0.__class__}'.format(1)\n",
    "format_map traversal": "s = '{x.__class__}'.format_map({'x': 1})\n",
    "f-string traversal": "s = f'{(1).__class__}'\n",
    "getattr with built names": "getattr(1, '__cl' + 'ass__')\n",
    "vars": "vars()\n",
    "globals": "globals()['__builtins__']\n",
    "fullwidth exec": "ｅｘｅｃ('import os')\n",
    "fullwidth eval": "ｅｖａｌ('1')\n",
    "fullwidth dunder attribute": "x = ().__ｃｌａｓｓ__\n",
    "eval": "eval('1 + 1')\n",
    "exec": "exec('x = 1')\n",
    "compile": "compile('1', 'f', 'eval')\n",
    "import os": "import os\n",
    "import as": "import os as o\n",
    "from import": "from os import system\n",
    "__import__": "__import__('os').system('id')\n",
    "importlib": "importlib.import_module('os')\n",
    "builtins dict": "__builtins__['open']('/etc/passwd')\n",
    "open": "open('/etc/passwd').read()\n",
    "open write": "open('pwned', 'w').write('x')\n",
    "breakpoint": "breakpoint()\n",
    "os.fork": "os.fork()\n",
    "socket": "socket.socket().connect(('127.0.0.1', 80))\n",
    "lambda closure": "f = lambda: 1\nf.__code__\n",
    "def": "def f():\n    return 1\n",
    "class": "class A:\n    pass\n",
    "type": "type(1)\n",
    "while True": "while True:\n    pass\n",
    "busy for": "for i in range(100000):\n    for j in range(100000):\n        x = i * j\n",
    "power bomb": "x = 10 ** 10 ** 9\n",
    "list bomb": "x = [0] * 10 ** 10\n",
    "string bomb": "x = 'a' * 10 ** 10\n",
    "deep list nesting": "x = " + "[" * 40 + "]" * 40 + "\n",
    "deep parentheses": "x = " + "(" * 300 + "1" + ")" * 300 + "\n",
    "deep if nesting": "".join("    " * i + "if True:\n" for i in range(30)) + "    " * 30 + "pass\n",
    "huge program": "x = 1\n" * 2000,
    "null byte": "x = 1\x00\n",
    "syntax error": "pick_and_place(obj=\n",
    "NaN argument": "pick_and_place(obj='a', xy=(float('nan'), 0.0))\n",
    "infinite argument": "pick_and_place(obj='a', xy=(float('inf'), 0.0))\n",
    "off-table argument": "pick_and_place(obj='a', xy=(3.0, 0.0))\n",
    "unknown object": "press(obj='ghost')\n",
    "unknown skill argument": "press(obj='a', force=100)\n",
    "too many calls": "for i in range(1000):\n    retreat()\n",
}


def scene() -> SceneSpec:
    return SceneSpec(objects=(ObjectSpec("a", "block", (0.5, -0.1)), ObjectSpec("b", "plate", (0.55, 0.1))))


def snapshot() -> SceneSnapshot:
    spec = scene()
    return SceneSnapshot({o.name: (o.xy[0], o.xy[1], 0.75, o.yaw) for o in spec.objects},
                         spec.table.x_range, spec.table.y_range, spec.table.height)


def skills() -> list[SkillSignature]:
    return api()


def blocked(result: RunResult) -> tuple[bool, str]:
    """Whether ``result`` is blocked, and by what (the sandbox's status or the parent's check)."""
    if not result.ok:
        return True, result.status
    try:
        for call in result.calls:
            check_call(call, scene())
    except SubtaskError:
        return True, "argument check"
    return False, "ran"
