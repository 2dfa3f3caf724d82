"""The resources location must be the FMU's own resources folder, in both families (issue 38,
F3): `file:///tmp`, or any folder without the FMU's files, makes fmi2Instantiate return NULL
with a message naming the folder. Before, the C family took it and ran without its files."""
import pytest

from fmi_host import FmiHost, unpack

pytestmark = pytest.mark.needs("gcc")


@pytest.fixture(scope="module")
def folders(unpacked, native_fmus, tmp_path_factory):
    """{family: unpacked SmaPwmDriver folder}."""
    native = unpack(native_fmus["SmaPwmDriver"], tmp_path_factory.mktemp("native") / "SmaPwmDriver")
    return {"python": unpacked["SmaPwmDriver"], "native": native}


def _instantiate(exe, folder, uri):
    """(status, error lines) of fmi2Instantiate with ``uri`` (hex text, or a keyword)."""
    with FmiHost(exe, folder) as host:
        reply = host.call(f"instantiate 0 {b'where'.hex()} {uri} ok 0")
        if reply.status == 0:
            host.call("free 0")
        return reply.status, reply.logged()


@pytest.mark.parametrize("family", ["python", "native"])
def test_a_folder_that_is_not_the_fmus_resources_is_refused(fmi_host_exe, folders, tmp_path, family):
    empty = tmp_path / "empty"
    empty.mkdir()
    for uri in ("file:///tmp", empty.as_uri(), (folders[family] / "binaries").as_uri()):
        status, errors = _instantiate(fmi_host_exe, folders[family], uri.encode().hex())
        assert status != 0 and errors, (family, uri)
        assert uri.split("file://", 1)[1] in errors[-1], (family, errors)
    assert _instantiate(fmi_host_exe, folders[family], "ok")[0] == 0
