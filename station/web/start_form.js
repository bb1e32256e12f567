// The live page's start form (issue 35): the protocol, the operator and a serial (and part) per
// slot of the rig (status.rig_slots), each field one a barcode scanner can type into. A scanner
// types the text then Enter: Enter moves to the next slot's serial and, after the last, to the
// Start button; only a click (or Enter on the button itself) sends the batch, never half of it.
// POST /api/runs {"protocol", "operator", "slots": {"1": {"serial", "part"}}} (schemas/api.md).
(function () {
  "use strict";

  function $(id) { return document.getElementById(id); }

  function field(id, label, value, hint) {
    var wrap = document.createElement("label");
    wrap.className = "start-field";
    wrap.appendChild(document.createTextNode(label + " "));
    var input = document.createElement("input");
    input.id = id;
    input.type = "text";
    input.value = value || "";
    input.autocomplete = "off";
    input.spellcheck = false;
    if (hint) input.placeholder = hint;
    wrap.appendChild(input);
    return wrap;
  }

  // Enter in a field: the next slot's serial (a part field is prefilled, clicked to change), or
  // after the last the Start button (never a submit).
  function onKey(e) {
    if (e.key !== "Enter" || e.target.tagName !== "INPUT") return;
    e.preventDefault();
    var order = [$("start-protocol"), $("start-operator")].concat(
        Array.prototype.slice.call($("start-slots").querySelectorAll("input.start-serial")));
    var at = e.target.dataset.after ? $(e.target.dataset.after) : e.target;
    var i = order.indexOf(at);
    var next = i >= 0 && i + 1 < order.length ? order[i + 1] : $("start-go");
    next.focus();
    if (next.select) next.select();
  }

  function build(slots) {
    var box = $("start-slots");
    box.textContent = "";
    slots.forEach(function (s) {
      var row = document.createElement("div");
      row.className = "start-slot";
      var serial = field("start-serial-" + s.slot, "slot " + s.slot + " (node " + s.node +
                         ") serial", s.serial, s.serial ? "" : "scan the serial");
      serial.querySelector("input").className = "start-serial";
      var part = field("start-part-" + s.slot, "part", s.part, "part number (optional)");
      part.querySelector("input").dataset.after = "start-serial-" + s.slot;
      row.appendChild(serial);
      row.appendChild(part);
      box.appendChild(row);
    });
  }

  // The start body, or a message saying which field is missing.
  function body(slots) {
    var protocol = $("start-protocol").value.trim();
    if (!protocol) return {error: "give a protocol"};
    var out = {protocol: protocol, operator: $("start-operator").value.trim(), slots: {}};
    for (var i = 0; i < slots.length; i++) {
      var n = String(slots[i].slot);
      var serial = $("start-serial-" + n).value.trim();
      var part = $("start-part-" + n).value.trim();
      if (!serial) return {error: "slot " + n + ": scan or type its serial"};
      out.slots[n] = part ? {serial: serial, part: part} : {serial: serial};
    }
    return {body: out};
  }

  var sendFn = null;
  var shown = [];

  function close() {
    $("start-form").hidden = true;
    $("start-error").textContent = "";
  }

  // Opens the form for the rig's slots of `status`; `send(body)` posts the start.
  function open(status, send) {
    sendFn = send;
    shown = status.rig_slots || [];
    build(shown);
    $("start-operator").value = sessionStorage.getItem("station.operator") || "";
    $("start-error").textContent = "";
    $("start-form").hidden = false;
    var first = shown.length ? $("start-serial-" + shown[0].slot) : $("start-protocol");
    first.focus();
    first.select();
  }

  function go() {
    var b = body(shown);
    if (b.error) {
      $("start-error").textContent = b.error;
      return;
    }
    sessionStorage.setItem("station.operator", b.body.operator);
    close();
    if (sendFn) sendFn(b.body);
  }

  function init() {
    $("start-go").addEventListener("click", go);
    $("start-cancel").addEventListener("click", close);
    $("start-form").addEventListener("keydown", onKey);
    $("start-form").addEventListener("input", function () { $("start-error").textContent = ""; });
  }

  window.StartForm = {open: open};
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", init);
  else init();
})();
