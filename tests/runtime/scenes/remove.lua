-- remove.lua OP A [B]: os.remove(A) or os.rename(A, B).
if arg[1] == "remove" then
  assert(os.remove(arg[2]))
else
  assert(os.rename(arg[2], arg[3]))
end
print(arg[1], "done")
