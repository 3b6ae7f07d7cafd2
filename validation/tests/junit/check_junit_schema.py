#!/usr/bin/env python3
"""Checks a JUnit XML file against what the Jenkins/Surefire JUnit schema (JUnit.xsd,
as Jenkins' junit plugin and GitLab read it) requires of elements and attributes.
Usage: check_junit_schema.py FILE. Prints every violation; exit 1 on any."""
import re
import sys
import xml.etree.ElementTree as ET

DATETIME = re.compile(r"^\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}$")   # xs:dateTime, no zone (the XSD's pattern)
DECIMAL = re.compile(r"^-?\d+(\.\d+)?([eE][-+]?\d+)?$")
problems = []


def need(el, attrs):
    for a in attrs:
        if a not in el.attrib:
            problems.append(f"<{el.tag}> lacks required attribute {a}")


def count(el, attr):
    v = el.attrib.get(attr, "")
    if not v.isdigit():
        problems.append(f"<{el.tag}> {attr}={v!r} is not a non-negative integer")
        return 0
    return int(v)


root = ET.parse(sys.argv[1]).getroot()
suites = [root] if root.tag == "testsuite" else list(root)
if root.tag not in ("testsuites", "testsuite"):
    problems.append(f"root element is <{root.tag}>")
for suite in suites:
    if suite.tag != "testsuite":
        problems.append(f"<testsuites> holds <{suite.tag}>")
        continue
    need(suite, ["name", "timestamp", "hostname", "tests", "failures", "errors", "time"])
    if not DATETIME.match(suite.attrib.get("timestamp", "")):
        problems.append(f"timestamp {suite.attrib.get('timestamp')!r} is not an xs:dateTime without zone")
    if not DECIMAL.match(suite.attrib.get("time", "")):
        problems.append(f"testsuite time {suite.attrib.get('time')!r} is not a decimal")
    children = [c.tag for c in suite]
    # The XSD's sequence: properties, testcase*, system-out, system-err.
    if not children or children[0] != "properties":
        problems.append("<testsuite> must begin with <properties>")
    if children[-2:] != ["system-out", "system-err"]:
        problems.append("<testsuite> must end with <system-out> and <system-err>")
    cases = [c for c in suite if c.tag == "testcase"]
    if any(t not in ("properties", "testcase", "system-out", "system-err") for t in children):
        problems.append(f"<testsuite> holds an unknown element: {children}")
    n_fail = n_err = n_skip = 0
    for case in cases:
        need(case, ["name", "classname", "time"])
        if not DECIMAL.match(case.attrib.get("time", "")):
            problems.append(f"testcase time {case.attrib.get('time')!r} is not a decimal")
        inner = [c.tag for c in case]
        if len(inner) > 1 or any(t not in ("error", "failure", "skipped") for t in inner):
            problems.append(f"<testcase> holds {inner}: at most one of error, failure, skipped")
        for c in case:
            if c.tag in ("error", "failure"):
                need(c, ["type", "message"])
            n_fail += c.tag == "failure"
            n_err += c.tag == "error"
            n_skip += c.tag == "skipped"
    if count(suite, "tests") != len(cases):
        problems.append(f"tests={suite.attrib.get('tests')} but {len(cases)} testcases")
    if count(suite, "failures") != n_fail:
        problems.append(f"failures={suite.attrib.get('failures')} but {n_fail} <failure>")
    if count(suite, "errors") != n_err:
        problems.append(f"errors={suite.attrib.get('errors')} but {n_err} <error>")
    if "skipped" in suite.attrib and count(suite, "skipped") != n_skip:
        problems.append(f"skipped={suite.attrib.get('skipped')} but {n_skip} <skipped>")
for p in problems:
    print(p)
sys.exit(1 if problems else 0)
