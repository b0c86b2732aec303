-- param_spec.lua — outcrop.param, outcrop.seed and outcrop.version, with
-- the registry settings the interpreter would make (oclua.h).
local oc = require "outcrop"
local R = require "helpers.ref"

local reg = debug.getregistry()

describe("outcrop.param", function()
  after_each(function() reg["outcrop.params"] = nil end)

  it("returns the default when no parameters are set", function()
    reg["outcrop.params"] = nil
    assert.are.equal(12, oc.param("size", 12))
    assert.is_nil(oc.param("size"))
    assert.are.equal("x", oc.param("name", "x"))
  end)

  it("parses numbers, booleans and strings", function()
    reg["outcrop.params"] = {size = "3", eps = "1e-2", hex = "0x10",
      flag = "true", off = "false", rock = "granite", neg = "-2.5",
      blank = "", spaced = " 7 "}
    assert.are.equal(3, oc.param("size", 1))
    assert.are.equal(math.type(oc.param("size")), "integer")
    assert.are.equal(0.01, oc.param("eps", 1))
    assert.are.equal(16, oc.param("hex"))
    assert.are.equal(true, oc.param("flag", false))
    assert.are.equal(false, oc.param("off", true))
    assert.are.equal("granite", oc.param("rock", "basalt"))
    assert.are.equal(-2.5, oc.param("neg"))
    assert.are.equal("", oc.param("blank", "d"))
    assert.are.equal(7, oc.param("spaced"))
    assert.are.equal("dflt", oc.param("absent", "dflt"))
  end)

  it("needs a string name", function()
    R.check_error(function() oc.param(3) end, "param_spec.lua", "outcrop.param", "name must be a string (got 3)")
    R.check_error(function() oc.param("a", 1, 2) end, "param_spec.lua", "outcrop.param", "too many arguments")
  end)
end)

describe("outcrop.seed", function()
  local saved
  before_each(function() saved = reg["outcrop.seed"] end)
  after_each(function() reg["outcrop.seed"] = saved end)

  it("defaults to 1", function()
    reg["outcrop.seed"] = nil
    assert.are.equal(1, oc.seed)
  end)

  it("shows the registry seed and is what constructors default to", function()
    reg["outcrop.seed"] = 42
    assert.are.equal(42, oc.seed)
    local a = oc.turbulence{wavelength = 1}
    local b = oc.turbulence{wavelength = 1, seed = 42}
    local c = oc.turbulence{wavelength = 1, seed = 1}
    local differ = false
    for i = 1, 20 do
      local p = {0.37 * i, 0.21 * i, -0.13 * i}
      assert.are.equal(b:eval(p), a:eval(p))
      if c:eval(p) ~= a:eval(p) then differ = true end
    end
    assert.is_true(differ)
  end)

  it("applies to warp and perturb too", function()
    local p = oc.point{center = {0, 0, 0}, radius = 2}
    reg["outcrop.seed"] = 9
    local w = oc.warp(p, {wavelength = 0.5, amplitude = 0.3})
    local q = oc.perturb(p, {wavelength = 0.5, amplitude = 0.3})
    reg["outcrop.seed"] = saved
    local w9 = oc.warp(p, {wavelength = 0.5, amplitude = 0.3, seed = 9})
    local q9 = oc.perturb(p, {wavelength = 0.5, amplitude = 0.3, seed = 9})
    for i = 1, 20 do
      local x = {0.07 * i, 0.05 * i, 0.02 * i}
      assert.are.equal(w9:eval(x), w:eval(x))
      assert.are.equal(q9:eval(x), q:eval(x))
    end
  end)

  it("ignores a malformed registry value", function()
    reg["outcrop.seed"] = -5
    assert.are.equal(1, oc.seed)
    reg["outcrop.seed"] = "abc"
    assert.are.equal(1, oc.seed)
  end)
end)

describe("outcrop.version", function()
  it("is a version string", function()
    assert.matches("^%d+%.%d+%.%d+", oc.version)
  end)
end)

describe("the module", function()
  it("lets scripts add their own fields", function()
    oc.my_helper = 5
    assert.are.equal(5, oc.my_helper)
    oc.my_helper = nil
  end)
end)
