-- hostile_spec.lua — scripts that close or collect objects while a binding
-- uses them: option tables whose __index closes things, colour and
-- density callbacks, finalizers of script objects (which run at any
-- allocation inside a binding), `<close>` in callbacks, outcrop.threshold
-- changed meanwhile. A call pins what it uses: a close is deferred until
-- it returns, and a closed object then gives a clean error. Under the
-- sanitizer pass a use after free shows as an ASan report.
local oc = require "outcrop"
local R = require "helpers.ref"
local G = require "helpers.gcstress"

local F = "hostile_spec.lua"

-- `local x <close>` is the script's only way to close an object early.
local function close(x)
  local c <close> = x
end

-- Calls `call` with the collector running a full cycle (and the pending
-- finalizers) at every allocation, and a finalizer that runs `action` at
-- the k-th of them (default 1). A chain of garbage objects keeps one
-- finalizer pending at each cycle until then. Returns whether the action
-- ran, then pcall's results.
local function during(call, action, k)
  local st = {go = false, fired = false, left = k or 1}
  local function link()
    setmetatable({}, {__gc = function()
      if st.go and not st.fired then
        st.left = st.left - 1
        if st.left == 0 then
          st.fired = true
          action()
          return
        end
      end
      if not st.fired and not st.done then link() end
    end})
  end
  link()
  -- pause 1 (0 would keep the current pause), the largest steps; the full
  -- collection makes the new pause count from now
  collectgarbage("incremental", 1, 1000, 40)
  collectgarbage()
  st.go = true
  local ok, a, b = pcall(call)
  st.go = false
  st.done = true
  G.restore()
  return st.fired, ok, a, b
end

-- Runs `action` from a finalizer at each of the first allocations inside
-- a binding in turn: `setup()` makes fresh objects and returns the call
-- and the action. Each run must either succeed (the close was deferred
-- until the call returned), checked by `check(result)`, or raise the clean
-- "was closed" error (the close came before the object was pinned). At
-- least one run must close the object while the call used it.
local function at_each_allocation(setup, check, n)
  local deferred = 0
  for k = 1, n or 6 do
    local call, action = setup()
    local fired, ok, r = during(call, action, k)
    if ok then
      check(r)
      if fired then deferred = deferred + 1 end
    else
      assert.matches("was closed", tostring(r))
    end
  end
  assert.is_true(deferred > 0, "no close ever happened during the call")
end

-- An options table whose every read runs `action` first.
local function trap(action, fields)
  return setmetatable({}, {__index = function(_, k)
    action()
    collectgarbage()
    return fields and fields[k]
  end})
end

local function same(a, b)
  if #a ~= #b then return false end
  for i = 1, #a do
    if a[i] ~= b[i] then return false end
  end
  return true
end

local function small_hf()
  return oc.heightfield.fbm{size = {9, 9}, amplitude = 1, wavelength = 4, seed = 2}
end

local ball = oc.point{center = {0, 0, 0}, radius = 2}

describe("hostile scripts", function()
  local dir
  before_each(function() dir = R.tmpdir() end)
  after_each(function()
    oc.threshold = 0.5
    G.restore()
    R.rmdir(dir)
  end)

  describe("option tables that close the object in use", function()
    it("hf:save", function()
      local hf = small_hf()
      local want = hf:sum()
      local lo, hi = hf:save(dir .. "/a.png", trap(function() close(hf) end))
      assert.is_number(lo)
      assert.is_number(hi)
      -- the close took effect when the call returned
      R.check_error(function() return hf:sum() end, F, "heightfield:sum", "the heightfield was closed")
      local back = oc.heightfield.load(dir .. "/a.png")
      assert.are.same({9, 9}, {back:size()})
      assert.is_true(want == want)
    end)

    it("heightfield analysis (drainage, accessibility)", function()
      local hf = small_hf()
      local d = hf:drainage(trap(function() close(hf) end))
      assert.are.same({9, 9}, {d:size()})
      local hf2 = small_hf()
      local a = hf2:accessibility(trap(function() close(hf2) end, {rays = 4}))
      assert.are.same({9, 9}, {a:size()})
      R.check_error(function() return hf2:min() end, F, "heightfield:min", "the heightfield was closed")
    end)

    it("resample and crop", function()
      local hf = small_hf()
      local r = hf:resample(trap(function() close(hf) end, {cell = 2}))
      assert.are.same({5, 5}, {r:size()})
      local hf2 = small_hf()
      local c = hf2:crop(setmetatable({1, 1, 4, 4}, {__index = function()
        close(hf2)
        collectgarbage()
      end}))
      assert.are.same({4, 4}, {c:size()})
    end)

    it("terrain: the grid closed by its options, the mask before it is read", function()
      local hf, mask = small_hf(), small_hf()
      local t = oc.terrain(hf, trap(function() close(hf) end, {falloff = 2}))
      assert.is_number(t:eval(4, 4, 0))
      local hf2 = small_hf()
      local opts = setmetatable({mask = mask}, {__index = function()
        close(mask)
        collectgarbage()
      end})
      R.check_error(function() return oc.terrain(hf2, opts) end, F, "outcrop.terrain",
        "the heightfield was closed")
    end)

    it("poisson2d with a heightfield density the options close", function()
      local hf = oc.heightfield.from(function() return 1 end, {size = {5, 5}, cell = 5})
      local opts = {box = {0, 0, 20, 20}, radius = 3, seed = 1, density = hf}
      setmetatable(opts, {__index = function()
        close(hf)
        opts.density = nil
        collectgarbage()
      end})
      local pts = oc.poisson2d(opts)
      assert.is_true(#pts > 0)
    end)

    it("image:write", function()
      local img = oc.slice(ball, {box = {-3, -3, 3, 3}, size = {8, 8}})
      assert.is_true(img:write(dir .. "/s.png", trap(function() close(img) end)))
      R.check_error(function() return img:size() end, F, "image:size", "the image was closed")
    end)

    it("polygonize keeps the colour node its options drop", function()
      local opts = {colors = {field = oc.point{center = {0, 0, 0}, radius = 3},
                              palette = {{0, {0, 0, 0}}, {1, {1, 1, 1}}}}}
      local colors = opts.colors
      setmetatable(colors, {__index = function()
        colors.field = nil
        collectgarbage()
      end})
      opts.resolution = {6, 6, 6}
      setmetatable(opts, {__index = function() collectgarbage() end})
      local m = oc.polygonize(ball, opts)
      assert.is_true(m:counts() > 0)
    end)
  end)

  describe("generators", function()
    it("keep the grid and nodes their options drop or close", function()
      local hf = oc.heightfield.fbm{size = {17, 17}, amplitude = 4, wavelength = 8, seed = 2}
      local opts = {heightfield = hf, terrain = oc.terrain(hf, {falloff = 2}),
                    geology = oc.geology.strata{wavelength = 5, seed = 9}}
      setmetatable(opts, {__index = function(t)
        rawset(t, "terrain", nil)
        rawset(t, "geology", nil)
        close(hf)
        collectgarbage()
      end})
      local n, info = oc.generate.sea(opts)
      assert.are.equal("blend", n:kind())
      assert.is_true(info.columns > 0)
      R.check_error(function() return hf:size() end, F, "heightfield:size", "the heightfield was closed")
    end)
  end)

  describe("callbacks that close things", function()
    it("a finalizer run by collectgarbage() in a colour function", function()
      local m = oc.polygonize(ball, {resolution = {6, 6, 6}})
      local armed = true
      local ok = m:write(dir .. "/g.ply", {colors = function()
        if armed then
          armed = false
          setmetatable({}, {__gc = function() close(m) end})
          collectgarbage()
        end
        return 1, 1, 1
      end})
      assert.is_true(ok)
      assert.are.equal("outcrop.mesh: (closed)", tostring(m))
    end)

    it("a coroutine abandoned in an error keeps its pins until it goes", function()
      local hf = small_hf()
      local co = coroutine.create(function()
        return hf:save(dir .. "/c.png", setmetatable({}, {__index = function()
          error("stop here")
        end}))
      end)
      local ok, err = coroutine.resume(co)
      assert.is_false(ok)
      assert.matches("stop here", err)
      close(hf) -- deferred: the dead coroutine's stack still pins it
      R.check_error(function() return hf:size() end, F, "heightfield:size", "the heightfield was closed")
      assert.is_true(coroutine.close(co) == false) -- closes the pin, frees the grid
      co = nil
      collectgarbage()
      assert.are.equal("outcrop.heightfield: (closed)", tostring(hf))
    end)

    it("mesh:write with a colour function closing the mesh", function()
      local m = oc.polygonize(ball, {resolution = {6, 6, 6}})
      local n = 0
      local ok = m:write(dir .. "/m.ply", {colors = function()
        n = n + 1
        close(m)
        collectgarbage()
        return 0.5, 0.5, 0.5
      end})
      assert.is_true(ok)
      assert.is_true(n > 0)
      R.check_error(function() return m:counts() end, F, "mesh:counts", "the mesh was closed")
    end)

    it("polygonize with a colour function changing the threshold", function()
      local m = oc.polygonize(ball, {resolution = {6, 6, 6}, colors = function()
        oc.threshold = 0.3 + math.random() * 0.4
        ball:eval(0, 0, 0)
        collectgarbage()
        return 1, 0, 0
      end})
      assert.is_true(m:counts() > 0)
    end)

    it("render with a colour function closing things and changing T", function()
      local hf = small_hf()
      local img = oc.render(ball, {size = {8, 8}, color = function()
        close(hf)
        oc.threshold = 0.4
        ball:eval(0, 0, 0)
        collectgarbage()
        return 0.2, 0.3, 0.4
      end})
      assert.are.same({8, 8}, {img:size()})
    end)

    it("heightfield.from with a function closing other grids", function()
      local other = small_hf()
      local hf = oc.heightfield.from(function(x, y)
        close(other)
        collectgarbage()
        return x + y
      end, {size = {3, 3}})
      assert.are.equal(4, hf:get(3, 3))
    end)
  end)

  describe("finalizers running inside a binding", function()
    it("close the heightfield being analysed", function()
      at_each_allocation(function()
        local hf = small_hf()
        return function() return hf:slope() end, function() close(hf) end
      end, function(r) assert.are.same({9, 9}, {r:size()}) end)
    end)

    it("close the heightfield being saved", function()
      at_each_allocation(function()
        local hf = small_hf()
        return function() return hf:save(dir .. "/h.png") end,
          function() close(hf) end
      end, function(lo) assert.is_number(lo) end, 10)
    end)

    it("close the point set being converted", function()
      at_each_allocation(function()
        local pts = oc.poisson2d{box = {0, 0, 30, 30}, radius = 2, seed = 3, flat = true}
        return function() return pts:table() end, function() close(pts) end
      end, function(t) assert.is_true(#t > 10) end)
    end)

    it("close the mesh being written", function()
      at_each_allocation(function()
        local m = oc.polygonize(ball, {resolution = {6, 6, 6}})
        local opts = {colors = {field = ball, palette = {{0, {0, 0, 0}}, {1, {1, 1, 1}}}}}
        return function() return m:write(dir .. "/f.ply", opts) end,
          function() close(m) end
      end, function(r) assert.is_true(r) end)
    end)

    it("close the image being written", function()
      at_each_allocation(function()
        local img = oc.slice(ball, {box = {-3, -3, 3, 3}, size = {8, 8}})
        return function() return img:write(dir .. "/f.png") end,
          function() close(img) end
      end, function(r) assert.is_true(r) end, 10)
    end)

    it("close the grid a terrain is made from", function()
      at_each_allocation(function()
        local hf, opts = small_hf(), {falloff = 2}
        return function() return oc.terrain(hf, opts) end, function() close(hf) end
      end, function(t) assert.is_number(t:eval(4, 4, 0)) end)
    end)

    it("close the density grid of poisson2d", function()
      at_each_allocation(function()
        local hf = oc.heightfield.from(function() return 1 end, {size = {5, 5}, cell = 5})
        local opts = {box = {0, 0, 20, 20}, radius = 3, seed = 1, density = hf}
        return function() return oc.poisson2d(opts) end, function() close(hf) end
      end, function(t) assert.is_true(#t > 0) end)
    end)

    -- A finalizer sets outcrop.threshold and queries the node at each of
    -- the first allocations of make(node): the result is checked by
    -- check(result, fired).
    local function threshold_changes(make, check)
      local node = oc.point{center = {0, 0, 0}, radius = 2}
      for k = 1, 6 do
        local fired, ok, r = during(function() return make(node) end, function()
          oc.threshold = 0.7
          node:eval(0, 0, 0)
        end, k)
        assert.is_true(ok, r)
        check(r, node)
        oc.threshold = 0.5
        if not fired then break end -- fewer allocations than k
      end
    end

    it("change the threshold while a slice uses the node's program", function()
      local opts = {box = {-3, -3, 3, 3}, size = {4, 4}}
      local want = {}
      threshold_changes(function(node) return oc.slice(node, opts) end, function(img, node)
        for _, T in ipairs{0.5, 0.7} do
          oc.threshold = T
          want[T] = want[T] or oc.slice(node, opts)
        end
        -- the slice is made whole at the threshold it read
        local same5, same7 = true, true
        for i = 1, 4 do
          for j = 1, 4 do
            local got = {img:get(i, j)}
            same5 = same5 and same(got, {want[0.5]:get(i, j)})
            same7 = same7 and same(got, {want[0.7]:get(i, j)})
          end
        end
        assert.is_true(same5 or same7)
      end)
    end)

    it("change the threshold while polygonize uses the node's program", function()
      local opts = {resolution = {6, 6, 6}}
      threshold_changes(function(node) return oc.polygonize(node, opts) end,
        function(m) assert.is_true(m:counts() > 0) end)
    end)

    it("change the threshold while render uses the node's program", function()
      local opts = {size = {6, 6}}
      threshold_changes(function(node) return oc.render(node, opts) end,
        function(img) assert.are.same({6, 6}, {img:size()}) end)
    end)
  end)

  describe("closed objects", function()
    it("give a clean error naming the function and the line", function()
      local hf = small_hf()
      close(hf)
      R.check_error(function() return hf:size() end, F, "heightfield:size", "the heightfield was closed")
      R.check_error(function() return hf:save(dir .. "/x.png") end, F, "heightfield:save", "the heightfield was closed")
      R.check_error(function() return oc.terrain(hf) end, F, "outcrop.terrain", "the heightfield was closed")
      R.check_error(function() return oc.poisson2d{box = {0, 0, 1, 1}, radius = 1, density = hf} end,
        F, "outcrop.poisson2d", "the heightfield was closed")
      local img = oc.slice(ball, {box = {-3, -3, 3, 3}, size = {4, 4}})
      close(img)
      R.check_error(function() return img:get(1, 1) end, F, "image:get", "the image was closed")
      local m = oc.polygonize(ball, {resolution = {4, 4, 4}})
      close(m)
      R.check_error(function() return m:vertex(1) end, F, "mesh:vertex", "the mesh was closed")
      local p = oc.poisson3d{box = {0, 0, 0, 4, 4, 4}, radius = 1, flat = true}
      close(p)
      R.check_error(function() return p:get(1) end, F, "points:get", "the point set was closed")
      assert.are.equal(0, #p)
    end)

    it("closing twice, or after the collector ran, is harmless", function()
      local hf = small_hf()
      close(hf)
      close(hf)
      assert.matches("closed", tostring(hf))
    end)
  end)

  describe("messages from nested options", function()
    it("name the exact field path", function()
      local pal = {{0, {0, 0, 0}}, {1, {2, 0, 0}}}
      R.check_error(function() oc.render(ball, {size = {4, 4}, color = {field = ball, palette = pal}}) end,
        F, "outcrop.render", "'color.palette[2]' colour components must be in [0, 1] (got r = 2)")
      R.check_error(function() oc.polygonize(ball, {colors = {field = ball, palette = {pal[1], "x"}}}) end,
        F, "outcrop.polygonize", "'colors.palette[2]' must be {value, {r, g, b}} (got string)")
      R.check_error(function() oc.render(ball, {camera = {[true] = 1}}) end,
        F, "outcrop.render", "unexpected key of type boolean of 'camera'")
      R.check_error(function() oc.render(ball, {camera = {1, 2}}) end,
        F, "outcrop.render", "unexpected array item [1] of 'camera'", "camera.eye = ...")
      R.check_error(function() oc.transform(ball, {rotate = {1, 2, nil, 4}}) end,
        F, "outcrop.transform", "the array part of 'rotate' must be a sequence")
      R.check_error(function() oc.transform(ball, {rotate = {axis = {0, 0, "x"}, angle = 1}}) end,
        F, "outcrop.transform", "'rotate.axis' must be a table of 3 numbers (item 3 is string)")
      local hf = small_hf()
      R.check_error(function() oc.generate.karst{heightfield = hf, sinks = {{1, 2, 3}, {1, "x", 3}}} end,
        F, "outcrop.generate.karst", "'sinks[2]' must be a table of 3 numbers (item 2 is string)")
    end)
  end)

  describe("protected metatables", function()
    it("hide every metatable the module makes", function()
      local objs = {
        ball,
        small_hf(),
        oc.slice(ball, {box = {-3, -3, 3, 3}, size = {4, 4}}),
        oc.polygonize(ball, {resolution = {4, 4, 4}}),
        oc.poisson2d{box = {0, 0, 4, 4}, radius = 1, flat = true},
      }
      for _, o in ipairs(objs) do
        local mt = getmetatable(o)
        assert.are_not.equal("table", type(mt))
      end
      assert.are.equal(1, ball:eval(0, 0, 0))
    end)
  end)
end)
