from __future__ import annotations

import subprocess
import sys
import textwrap


def test_only_the_importing_packages_statements_get_stand_ins_which_load_the_real_module_on_use(tmp_path):
    """While a package is imported with some of its imports deferred, its own statements get stand-ins that
    load the real module on use; the same imports from anywhere else get the real modules at once."""
    package = tmp_path / "deferring_pkg"
    package.mkdir()
    (package / "__init__.py").write_text(
        textwrap.dedent(
            """
            from xmlrpc.client import dumps
            import xmlrpc.server as server
            from . import inner
            """
        )
    )
    (package / "inner.py").write_text("import xmlrpc.client\n")
    (tmp_path / "bystander.py").write_text("import xmlrpc.client\nfrom email.message import Message\n")
    script = textwrap.dedent(
        """
        import sys
        from kinema.motion.toppra_import import _deferring_imports_of
        with _deferring_imports_of(("xmlrpc", "email"), importer="deferring_pkg"):
            import deferring_pkg
            loaded_inside = sorted(m for m in ("xmlrpc.client", "xmlrpc.server") if m in sys.modules)
            import bystander
            print(bystander.xmlrpc.client is sys.modules["xmlrpc.client"], type(bystander.Message).__name__)
        print(loaded_inside, "xmlrpc.server" in sys.modules)
        print("<int>1</int>" in deferring_pkg.dumps((1,)), deferring_pkg.server.SimpleXMLRPCServer.__name__)
        print(deferring_pkg.inner.xmlrpc.client.dumps is sys.modules["xmlrpc.client"].dumps)
        import builtins
        print(type(builtins.__import__).__name__)  # the built-in one again
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "True type",
        "[] False",
        "True SimpleXMLRPCServer",
        "True",
        "builtin_function_or_method",
    ]
