"""Freed instances (issue 21): fmi2FreeInstance twice, or any call after it, is refused.

FMI 2.0 leaves such calls undefined; pythonfmu alone crashes on them (SIGSEGV). The front
keeps its live instances in a registry, and a freed instance's memory for a while, so it
knows a freed pointer when it sees one: the call returns fmi2Error (nothing for
fmi2FreeInstance), one line on stderr names the function and the instance, and the
process goes on. The host's logger is not called: after fmi2FreeInstance the host may
have freed what its logger needs.
"""
import pytest

from fmi_host import ERROR, OK, FmiHost, text


def _finish(host):
    """End the host; returns (exit status, its stderr)."""
    host.process.stdin.write("end\n")
    host.process.stdin.close()
    code = host.process.wait(timeout=60)
    return code, host.process.stderr.read()


def _started(host, slot=0, name="plant"):
    assert host.call(f"instantiate {slot} {text(name)} ok ok 0").status == OK
    for line in (f"setup {slot} 0 -", f"enter {slot}", f"exit {slot}"):
        assert host.call(line).status == OK


CALLS_AFTER_FREE = ["step 0 0 0.001", "getreal 0 1 2", "setreal 0 1 0 1.0", "terminate 0", "reset 0",
                    "getstate 0 0", "enter 0", "boolstatus 0 3", "debuglog 0 1 0"]


@pytest.mark.parametrize("call", CALLS_AFTER_FREE)
def test_a_call_after_free_is_refused_and_logged(fmi_host_exe, unpacked, call):
    host = FmiHost(fmi_host_exe, unpacked["SmaActuator"])
    _started(host)
    assert host.call("step 0 0 0.001").status == OK
    assert host.call("free 0").status == OK
    assert host.call("reuse 0").status == OK   # the host keeps using the freed pointer
    assert host.call(call).status == ERROR
    assert host.call("free 0").status == OK    # freed twice: refused (void)
    assert host.call("forget 0").status == OK
    _started(host, 1, "next")                  # the process and the FMU go on
    assert host.call("step 1 0 0.001").status == OK
    code, stderr = _finish(host)
    assert code == 0
    function = "fmi2" + {"step": "DoStep", "getreal": "GetReal", "setreal": "SetReal",
                         "terminate": "Terminate", "reset": "Reset", "getstate": "GetFMUstate",
                         "enter": "EnterInitializationMode", "boolstatus": "GetBooleanStatus",
                         "debuglog": "SetDebugLogging"}[call.split()[0]]
    assert f"sma-fmu front: {function}: refused: instance 'plant' was freed by fmi2FreeInstance" in stderr
    assert ("sma-fmu front: fmi2FreeInstance: refused: instance 'plant' was freed by "
            "fmi2FreeInstance") in stderr


def test_a_pointer_that_never_was_an_instance_is_refused(fmi_host_exe, unpacked):
    host = FmiHost(fmi_host_exe, unpacked["SmaFeedforward"])
    _started(host)
    assert host.call("bogus 1").status == OK
    assert host.call("step 1 0 0.001").status == ERROR
    assert host.call("free 1").status == OK
    assert host.call("forget 1").status == OK
    assert host.call("step 0 0 0.001").status == OK
    code, stderr = _finish(host)
    assert code == 0
    assert stderr.count("is not an instance of this FMU") == 2


def test_many_freed_instances_keep_refusing_and_the_registry_stays_usable(fmi_host_exe, unpacked):
    """Instances made and freed in turn (the kept freed instances cycle); each freed pointer
    is refused while the next instance is live."""
    host = FmiHost(fmi_host_exe, unpacked["SmaActuator"])
    for k in range(40):
        assert host.call(f"instantiate 0 {text(f'p{k}')} ok ok 0").status == OK
        assert host.call("free 0").status == OK
        assert host.call("reuse 0").status == OK
        assert host.call("terminate 0").status == ERROR
        assert host.call("forget 0").status == OK
    code, stderr = _finish(host)
    assert code == 0 and stderr.count("was freed by fmi2FreeInstance") == 40
